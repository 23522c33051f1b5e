// Patch tessellation evaluation shader: evaluates the bicubic (rational) Bezier patch at the
// tessellator's (u, v), control point (i, j) = tcs_point[4*j + i] (patch.h), and optionally
// displaces it along the unit normal by D(s,t) = scale * (h(s,t) - midlevel) from the height map,
// (s,t) interpolated bilinearly from the patch's corner texcoords (displacement.h). The shading
// normal is du x dv of the patch's ACC tangent patches when it has them (Loop & Schaefer 2008:
// continuous across extraordinary vertices), else of its own derivatives; displacement always
// follows the latter, which the cone bounds of Niessner & Loop §4.2 bound (gl_renderer.h).
#version 450 core
#include "shared.h"
#include "draw_params.h"
#define PC_MAX_DISPLACEMENT readonly
#define PC_PATCH_TEXCOORDS readonly
#define PC_PATCH_TANGENTS readonly
#include "patch_buffers.h"
#include "patch_eval.h"
#include "patch_displaced.h"

layout(quads, equal_spacing, ccw) in;

layout(binding = kTextureUnitDisplacement) uniform sampler2D u_displacement_map;

in vec4 tcs_point[];
patch in uint tcs_patch;

out vec3 tes_position;  // object space, displaced
out vec3 tes_normal;    // object space, unnormalized (zero at degenerate points): the shading normal
flat out uint tes_patch;
out vec2 tes_uv;        // the tessellator's (u, v): the fragment shader re-evaluates the surface there
// The mark-front pass (PATCHCULL_MARK_FRONT) is another program with the same TES source: the
// same gl_Position in both, so its GL_EQUAL depth test matches the reference's depth exactly.
// (Vulkan: the same SPIR-V module in both pipelines; Mesa's SPIR-V reader refuses the Invariant
// decoration glslang puts on gl_PerVertex's member, and the renderer's verification also counts
// every patch of the reference's id image as front: vk_renderer.h.)
#ifndef PC_VULKAN
invariant gl_Position;
#endif

// Quadratic Bernstein polynomials.
vec3 bernstein2(float t) {
    const float s = 1.0 - t;
    return vec3(s * s, 2.0 * t * s, t * t);
}

// du x dv of the tangent patches starting at patch_tangents[base] (patch.h's TangentPatches:
// du[3*j + i] of degree (2, 3), dv[4*j + i] of degree (3, 2)) at (u, v).
vec3 tangent_patch_normal(uint base, vec4 bu, vec4 bv, float u, float v) {
    const vec3 qu = bernstein2(u), qv = bernstein2(v);
    vec3 du = vec3(0.0), dv = vec3(0.0);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 3; ++i) du += qu[i] * bv[j] * patch_tangents[base + uint(3 * j + i)].xyz;
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) dv += bu[i] * qv[j] * patch_tangents[base + 12u + uint(4 * j + i)].xyz;
    return cross(du, dv);
}

void main() {
    const float u = gl_TessCoord.x;
    const float v = gl_TessCoord.y;
    vec4 cp[16];
    for (int k = 0; k < 16; ++k) cp[k] = tcs_point[k];
    vec3 p, pu, pv;
    vec4 bu, bv;
    evaluate_patch(cp, u, v, p, pu, pv, bu, bv);
    const vec3 n = cross(pu, pv);
    const float len = length(n);

    vec3 position = p;
    if (len > 0.0 && patch_is_displaced(tcs_patch)) {
        const uint base = 4u * tcs_patch;
        const vec2 st = mix(mix(patch_texcoords[base], patch_texcoords[base + 1u], u),
                            mix(patch_texcoords[base + 2u], patch_texcoords[base + 3u], u), v);
        const float height = texture(u_displacement_map, st).r;
        position += (u_displacement_scale * (height - u_displacement_midlevel) / len) * n;
    }
    tes_position = position;
    const uint tangent_base = kTangentVec4s * tcs_patch;
    const bool has_tangents = u_has_tangents && patch_tangents[tangent_base].w == 1.0;
    tes_normal = has_tangents ? tangent_patch_normal(tangent_base, bu, bv, u, v) : n;
    tes_patch = tcs_patch;
    tes_uv = vec2(u, v);
    gl_Position = u_object_to_clip * vec4(position, 1.0);
}
