// Patch fragment shader: patch id = patch index + 1 (0 is the background); colour = a per-patch
// hue (kColorPatch) or the patch's status in its flag word (kColorStatus, the legend of
// gl_renderer.h's render_status_image), shaded two-sided by the angle to the eye.
//
// One-sided surfaces (u_discard_back_facing, RenderParams::discard_back_facing; displaced patches
// excepted, patch_displaced.h): a closed,
// outward-oriented surface contributes only the points whose exact tangent plane faces the eye.
// The fragment re-evaluates the patch at its interpolated (u, v) (patch_eval.h, the TES's own
// evaluation) and is discarded unless cos(normal, to eye) > kFrontFacingMinCosine. This is the
// visibility that the back-patch tests of Loop, Niessner & Eisenacher ("Effective Back-Patch
// Culling for Hardware Tessellation") decide on, whatever the tessellation: secant triangles that
// face the eye while the surface does not, and cracks between patches (through which the inside
// of a closed surface would show), never put a back-facing point on screen.
//
// PATCHCULL_MARK_FRONT (the mark-front pass, PatchRenderer::mark_front_patches): early depth test
// GL_EQUAL against the reference's depth buffer, no colour or depth writes; a fragment that passes
// (and is kept by the test above) marks its patch, so every patch with a fragment at the front
// depth is found, including both sides of a depth tie.
#version 450 core
#include "shared.h"
#include "draw_params.h"
#define PC_CONTROL_POINTS readonly
#define PC_CULL_FLAGS readonly
#define PC_MAX_DISPLACEMENT readonly
#ifdef PATCHCULL_MARK_FRONT
#define PC_PATCH_MARKS writeonly
#endif
#include "patch_buffers.h"
#include "patch_eval.h"
#include "patch_displaced.h"

#ifdef PATCHCULL_MARK_FRONT
layout(early_fragment_tests) in;
#endif

in vec3 tes_position;
in vec3 tes_normal;
flat in uint tes_patch;
in vec2 tes_uv;

layout(location = 0) out vec4 out_color;
layout(location = 1) out uint out_id;

vec3 patch_hue(uint p) {
    uint h = p * 0x9E3779B9u;
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    return 0.35 + 0.65 * vec3(float(h & 255u), float((h >> 8) & 255u), float((h >> 16) & 255u)) / 255.0;
}

vec3 status_color(uint word) {
    if ((word & kCullFrustum) != 0u) return vec3(0.25, 0.45, 1.0);    // blue: frustum-culled
    if ((word & kCullBackPatch) != 0u) return vec3(0.85, 0.3, 0.9);   // magenta: back-patch-culled
    if ((word & kCullOcclusion) != 0u) return vec3(1.0, 0.2, 0.15);   // red: occlusion-culled
    if ((word & kCullObject) != 0u) return vec3(0.1, 0.75, 0.8);      // cyan: culled with its object
    if ((word & kStatusNewlyVisible) != 0u) return vec3(1.0, 0.85, 0.1);  // yellow: newly visible
    if ((word & kStatusVisible) != 0u) return vec3(0.2, 0.85, 0.3);   // green: visible
    return vec3(0.6, 0.6, 0.6);                                        // grey: no status yet
}

// The exact surface at the fragment's (u, v) faces the eye (by more than the grazing margin).
bool surface_faces_eye() {
    vec4 cp[16];
    for (int k = 0; k < 16; ++k) cp[k] = control_points[16u * tes_patch + uint(k)];
    const vec2 uv = clamp(tes_uv, 0.0, 1.0);  // interpolation may round just outside the domain
    vec3 p, pu, pv;
    vec4 bu, bv;
    evaluate_patch(cp, uv.x, uv.y, p, pu, pv, bu, bv);
    const vec3 n = cross(pu, pv);
    const vec3 to_eye = u_eye - p;
    return dot(n, to_eye) > kFrontFacingMinCosine * length(n) * length(to_eye);
}

void main() {
    if (u_discard_back_facing && !patch_is_displaced(tes_patch) && !surface_faces_eye()) discard;
#ifdef PATCHCULL_MARK_FRONT
    patch_marks[tes_patch] = 1u;
#endif
    const float len = length(tes_normal);
    const vec3 to_eye = normalize(u_eye - tes_position);
    const float facing = len > 0.0 ? abs(dot(tes_normal / len, to_eye)) : 1.0;
    const vec3 base = u_color_mode == kColorStatus ? status_color(cull_flags[tes_patch]) : patch_hue(tes_patch);
    out_color = vec4(base * (0.25 + 0.75 * facing), 1.0);
    out_id = tes_patch + 1u;
}
