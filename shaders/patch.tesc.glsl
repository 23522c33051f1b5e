// Patch tessellation control shader: passes the 16 control points through and sets the
// tessellation factors. A patch that is not to be drawn gets outer and inner levels 0, so the
// tessellator discards it (Niessner & Loop §3: the decision lands where the tessellator reads it).
// Drawn iff (flag word & u_draw_mask) == u_draw_value: the selections of shaders/patchcull_tcs.h
// (the include an engine's TCS uses; this shader is its first user).
//
// Levels: uniform u_tess_level times the patch's depth scale (kBindingPatchTessScale: patches of
// different refinement depth get equal vertex density, so shared edges match) on every edge and
// the interior, or adaptive by distance (Niessner & Loop
// §6.3, like DirectX's DetailTessellation11): edge level = clamp(u_tess_level * u_tess_reference /
// distance(eye, midpoint of the edge's two corner points), 1, u_tess_level), inner levels the max
// of the two opposite edges. An edge's level depends only on its two corner points (symmetric in
// them), so two patches sharing an edge give it the same level.
#version 450 core
#include "shared.h"
#include "draw_params.h"
#define PC_PATCH_TESS_SCALE readonly
// Drawn patches of this render (PatchRenderer::read_drawn_patches: what --verify compares). Not in
// the mark-front program (PATCHCULL_MARK_FRONT), whose fragment shader writes the same buffer: no
// two stages of one pipeline write it.
#ifndef PATCHCULL_MARK_FRONT
#define PC_PATCH_MARKS writeonly
#endif
#include "patch_buffers.h"
#include "patchcull_tcs.h"

layout(vertices = 16) out;

in vec4 vs_point[];
flat in uint vs_patch[];
out vec4 tcs_point[];
patch out uint tcs_patch;

float edge_level(vec4 a, vec4 b) {
    const vec3 mid = 0.5 * (a.xyz / a.w + b.xyz / b.w);
    const float d = max(distance(mid, u_eye), 1e-20);
    return clamp(u_tess_level * u_tess_reference / d, 1.0, u_tess_level);
}

void main() {
    tcs_point[gl_InvocationID] = vs_point[gl_InvocationID];
    if (gl_InvocationID == 0) {
        const uint p = vs_patch[0];
        const bool drawn = patchcull_patch_drawn(p, u_draw_mask, u_draw_value);
        vec4 outer = vec4(min(u_tess_level * patch_tess_scale[p], 64.0));
        if (u_adaptive) {
            // Quad domain: outer[0] is the edge u = 0, [1] v = 0, [2] u = 1, [3] v = 1; control
            // point (i, j) (u index i) is vs_point[4j + i].
            outer = vec4(edge_level(vs_point[0], vs_point[12]), edge_level(vs_point[0], vs_point[3]),
                         edge_level(vs_point[3], vs_point[15]), edge_level(vs_point[12], vs_point[15]));
        }
#ifndef PATCHCULL_MARK_FRONT
        if (drawn && u_mark_drawn) patch_marks[p] = 1u;
#endif
        gl_TessLevelOuter[0] = outer[0];
        gl_TessLevelOuter[1] = outer[1];
        gl_TessLevelOuter[2] = outer[2];
        gl_TessLevelOuter[3] = outer[3];
        gl_TessLevelInner[0] = max(outer[1], outer[3]);
        gl_TessLevelInner[1] = max(outer[0], outer[2]);
        if (!drawn) patchcull_skip_patch();
        tcs_patch = p;
    }
}
