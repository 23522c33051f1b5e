// Displaced-AABB frustum pass (FrustumDispPass, src/gl/frustum_disp_pass.cpp), one invocation per
// patch: the GPU twin of cull_frustum_disp_scalar (include/patchcull/core/frustum.h, src/core/frustum.cpp),
// Sathe's test ("View Frustum Culling of Catmull-Clark Patches in DirectX 11", Game Programming
// Gems 8): the object-space AABB of the Cartesian control points, grown by the patch's max |D| on
// every side, its 8 corners taken to clip space and tested against the clip planes.
//
// Same arithmetic as the CPU kernel, operation by operation, so the decisions are identical:
// X / W correctly rounded (pc_div: GLSL allows 2.5 ulp for a / b, backpatch_exact.h corrects it),
// min/max as the CPU's `a < b ? a : b`, each corner coordinate fma(m0, x, fma(m1, y, fma(m2, z,
// m3))) with pc_fma (exactly rounded also on llvmpipe, exact_fma.h), the plane values as separate
// adds and subtracts, `precise` everywhere so that the compiler neither contracts nor reassociates.
// A link of the flag chain (gl_passes.h): a patch that an earlier pass culled is left as it is;
// otherwise a culled patch gets the reason kCullFrustum.
// With PC_PATCH_SOURCE the points come from the caller's patch source (patch_source.h: Bezier or
// converted B-spline points; with PC_PATCH_SOURCE_GREGORY the box of a Gregory patch's 20 points,
// as cull_frustum_disp over a PatchSourceView).
#version 450 core
#include "shared.h"
#include "pass_params.h"
#define PC_CONTROL_POINTS readonly
#define PC_CULL_FLAGS
#define PC_MAX_DISPLACEMENT readonly
#define PC_PLANE_VALUES writeonly  // written only when write_plane_values
#include "patch_buffers.h"
#include "exact_fma.h"
#include "backpatch_exact.h"
#include "flag_chain.h"
#include "patch_source.h"

#ifdef PC_PATCH_SOURCE
#define PC_BOX_POINT(p, k) pc_source_points[k]
#define PC_BOX_POINT_COUNT PC_SOURCE_POINTS
#else
#define PC_BOX_POINT(p, k) control_points[16u * (p) + (k)]
#define PC_BOX_POINT_COUNT 16u
#endif

layout(local_size_x = kCullGroupSize) in;

// Corner c (= i*4 + j*2 + s, as the CPU kernel numbers them) of box (x from box[0][i], y from
// box[1][j], z from box[2][s]) in clip-space row r.
float pc_corner_row(int r, vec2 bx, vec2 by, vec2 bz, int c) {
    const vec4 m = frustum_disp.clip_rows[r];
    precise float tz = pc_fma(m.z, bz[c & 1], m.w);
    precise float tyz = pc_fma(m.y, by[(c >> 1) & 1], tz);
    precise float v = pc_fma(m.x, bx[c >> 2], tyz);
    return v;
}

void main() {
    const uint p = frustum_disp.first_patch + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= frustum_disp.patch_count || pc_chain_culled(p)) return;
#ifdef PC_PATCH_SOURCE
    if (!pc_gather_source(p)) return;  // an index past the points: left unculled
#endif
    const float d = pc_margin(p, frustum_disp.has_margins);

    // The Cartesian AABB of the 16 control points (a Gregory patch's 20).
    // A NaN or infinite coordinate anywhere: never culled (frustum.h, "Non-finite input").
    const vec4 p0 = PC_BOX_POINT(p, 0u);
    precise float lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = pc_div(p0[a], p0.w);
        hi[a] = lo[a];
    }
    bool non_finite = false;
    for (uint k = 0u; k < PC_BOX_POINT_COUNT; ++k) {
        const vec4 point = PC_BOX_POINT(p, k);
        for (int a = 0; a < 4; ++a)
            non_finite = non_finite || (floatBitsToUint(point[a]) & 0x7F800000u) == 0x7F800000u;
        if (k == 0u) continue;
        for (int a = 0; a < 3; ++a) {
            const float v = pc_div(point[a], point.w);
            lo[a] = pc_min_like(lo[a], v);
            hi[a] = pc_max_like(hi[a], v);
        }
    }
    // Grown by max |D| on every side: the displaced surface moves at most |D| from the base
    // surface, which lies in the control points' convex hull, inside the AABB.
    precise vec2 bx = vec2(lo[0] - d, hi[0] + d);
    precise vec2 by = vec2(lo[1] - d, hi[1] + d);
    precise vec2 bz = vec2(lo[2] - d, hi[2] + d);

    precise float mx[6];
    for (int c = 0; c < 8; ++c) {
        const float cx = pc_corner_row(0, bx, by, bz, c);
        const float cy = pc_corner_row(1, bx, by, bz, c);
        const float cz = pc_corner_row(2, bx, by, bz, c);
        const float cw = pc_corner_row(3, bx, by, bz, c);
        precise float v[6];
        v[0] = cw + cx;  // left
        v[1] = cw - cx;  // right
        v[2] = cw + cy;  // bottom
        v[3] = cw - cy;  // top
        v[4] = cz + frustum_disp.plane_depth.x * cw;  // near: k + near_w w
        v[5] = frustum_disp.plane_depth.y * cw - cz;  // far: far_w w - k
        for (int q = 0; q < 6; ++q) mx[q] = c == 0 ? v[q] : pc_max_like(mx[q], v[q]);
    }
    bool culled = mx[5] < frustum_disp.plane_depth.z;
    for (int q = 0; q < 5; ++q) culled = culled || mx[q] < 0.0;
    if (culled && !non_finite) pc_chain_cull(p, kCullFrustum);
    if (frustum_disp.write_plane_values != 0u)
        for (int q = 0; q < 6; ++q) plane_values[6u * p + uint(q)] = mx[q];
}
