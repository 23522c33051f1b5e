// Hi-Z occlusion cull pass (OcclusionPass, src/gl/occlusion_pass.cpp; seed 000 §4.1.1), one
// invocation per patch: the GPU twin of cull_occlusion_scalar (include/patchcull/hiz.h,
// src/core/hiz.cpp), steps numbered as in hiz.h. Operation by operation the same arithmetic, so the
// decisions are identical: products and std::fma <-> `precise` products and pc_fma (exact_fma.h),
// `a < b ? a : b` min/max, floor, integer shifts; the divisions of step 4 are correctly rounded
// (pc_div below).
// A link of the flag chain (flag_chain.h): patches culled earlier in the frame are skipped; then,
// as the CPU kernel, the frustum test (frustum_test.h, with the margin; when with_frustum) and
// steps 2-9 against the pyramid, only for patches whose margin is 0 (a displaced patch needs the
// bound of displaced.comp.glsl). Reasons kCullFrustum / kCullOcclusion.
#version 450 core
#include "shared.h"
#include "pass_params.h"
#include "exact_fma.h"
#include "flag_chain.h"

layout(local_size_x = kCullGroupSize) in;

layout(std430, binding = kBindingControlPoints) readonly buffer ControlPoints {
    vec4 control_points[];
};
layout(binding = kTextureUnitHiZ) uniform sampler2D u_hiz;

// frustum_test.h's and hiz_box_test.h's names.
#define u_clip_rows occlusion.clip_rows
#define u_plane_normal_length occlusion.plane_normal_length
#define u_screen ivec2(occlusion.screen_width, occlusion.screen_height)
#define u_hiz_levels occlusion.hiz_levels
#define u_object_to_clip occlusion.object_to_clip

#include "frustum_test.h"
#include "hiz_box_test.h"

float pc_min(float a, float b) { return a < b ? a : b; }
float pc_max(float a, float b) { return a > b ? a : b; }

// a / b correctly rounded (IEEE), as the CPU's float division. GLSL allows 2.5 ulp for float
// division, so it is computed in double and rounded once to float: for float a, b the exact
// quotient lies at least 2^-49 (relative) from every midpoint between two floats (a/b = midpoint
// m would need m*b, with m's odd 25-bit significand, to fit a 24-bit significand), farther than
// the error of any double division within 16 double ulps (2^-48 relative); so the float nearest
// to the double quotient is the float nearest to a/b.
float pc_div(float a, float b) {
    precise double q = double(a) / double(b);
    return float(q);
}

// 2^-20: step 3's safety factor (hiz.cpp kWSafety).
const float kWSafety = 9.5367431640625e-07;

// Steps 2-9 for patch p: true when the patch lies behind the pyramid.
bool hiz_occluded(uint p) {
    precise float nxmin = 0.0, nxmax = 0.0, nymin = 0.0, nymax = 0.0, zmin = 0.0;
    for (uint k = 0u; k < 16u; ++k) {
        const vec4 P = control_points[16u * p + k];
        // Step 2: clip-space point, c_r = fma(M(r,3), W, fma(M(r,2), Z, fma(M(r,1), Y, M(r,0) * X))).
        precise float c[4];
        for (int r = 0; r < 4; ++r) {
            precise float t = u_object_to_clip[0][r] * P.x;
            t = pc_fma(u_object_to_clip[1][r], P.y, t);
            t = pc_fma(u_object_to_clip[2][r], P.z, t);
            c[r] = pc_fma(u_object_to_clip[3][r], P.w, t);
        }
        // Step 3: projectable (provably w > 0), else the patch is not screen-tested.
        precise float s = abs(u_object_to_clip[0][3]) * abs(P.x);
        s = pc_fma(abs(u_object_to_clip[1][3]), abs(P.y), s);
        s = pc_fma(abs(u_object_to_clip[2][3]), abs(P.z), s);
        s = pc_fma(abs(u_object_to_clip[3][3]), abs(P.w), s);
        precise float bound = kWSafety * s;
        if (!(c[3] > bound)) return false;
        // Step 4: NDC box and front plane.
        const float nx = pc_div(c[0], c[3]);
        const float ny = pc_div(c[1], c[3]);
        const float nz = pc_div(c[2], c[3]);
        if (k == 0u) {
            nxmin = nx;
            nxmax = nx;
            nymin = ny;
            nymax = ny;
            zmin = nz;
        } else {
            nxmin = pc_min(nxmin, nx);
            nxmax = pc_max(nxmax, nx);
            nymin = pc_min(nymin, ny);
            nymax = pc_max(nymax, ny);
            zmin = pc_min(zmin, nz);
        }
    }
    return hiz_box_occluded(nxmin, nxmax, nymin, nymax, zmin);  // steps 5-9
}

void main() {
    const uint p = occlusion.first_patch + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= occlusion.patch_count || pc_chain_culled(p)) return;
    const float d = pc_margin(p, occlusion.has_margins);
    if (occlusion.with_frustum != 0u) {
        float mx[6];
        if (pc_frustum_culled(p, occlusion.has_margins != 0u, d, mx)) {
            pc_chain_cull(p, kCullFrustum);
            return;
        }
    }
    if (d == 0.0 && hiz_occluded(p)) pc_chain_cull(p, kCullOcclusion);
}
