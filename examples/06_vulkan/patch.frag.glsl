// examples/06_vulkan/patch.frag.glsl: writes the patch id, patch + 1 (0 = background), into the
// R32_UINT attachment the program compares.
//
// The one-sided rule for the closed object (the patches [u.one_sided.x, u.one_sided.y)): the
// back-patch tests (Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for Hardware
// Tessellation") decide on the EXACT surface: a patch is culled when no point of it faces the eye.
// The tessellated triangles are secants: near a silhouette a triangle of a patch that faces away
// can still cover pixels (and cracks between patches show the inside). So the fragment re-evaluates
// the patch at its (u, v) and is discarded unless the tangent plane there faces the eye (by more
// than a grazing margin of cos 1e-3): what patchcull's own renderer does. Hardware back-face
// culling of the triangles would NOT be the same rule. The open teapot is drawn two-sided.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(location = 0) in vec2 tes_uv;
layout(location = 1) flat in uint tes_patch;
layout(location = 0) out uint out_id;

const float kMinFacingCosine = 1.0e-3;

bool surface_faces_eye(uint patch_index) {
    vec4 cp[16];
    for (int k = 0; k < 16; ++k) cp[k] = control_points[16u * patch_index + uint(k)];
    vec3 p, pu, pv;
    evaluate_patch(cp, clamp(tes_uv, 0.0, 1.0), p, pu, pv);  // interpolation may leave [0, 1] by an ulp
    vec3 n = cross(pu, pv), to_eye = u.eye_level.xyz - p;
    return dot(n, to_eye) > kMinFacingCosine * length(n) * length(to_eye);
}

void main() {
    if (tes_patch >= u.one_sided.x && tes_patch < u.one_sided.y && !surface_faces_eye(tes_patch)) discard;
    out_id = tes_patch + 1u;
}
