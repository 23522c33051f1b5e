// Hi-Z occlusion cull pass (OcclusionPass, src/gl/occlusion_pass.cpp; Niessner & Loop §4.1.1), one
// invocation per patch: the GPU twin of cull_occlusion_scalar (include/patchcull/core/hiz.h,
// src/core/hiz.cpp), steps numbered as in hiz.h. Operation by operation the same arithmetic, so the
// decisions are identical: products and std::fma <-> `precise` products and pc_fma (exact_fma.h),
// `a < b ? a : b` min/max, floor, integer shifts; the divisions of step 4 are correctly rounded
// (hiz_div, hiz_box_test.h).
// A link of the flag chain (flag_chain.h): patches culled earlier in the frame are skipped; then,
// as the CPU kernel, the frustum test (frustum_test.h, with the margin; when with_frustum) and
// steps 2-9 against the pyramid, only for patches whose margin is 0 (a displaced patch needs the
// bound of displaced.comp.glsl). Reasons kCullFrustum / kCullOcclusion.
// With PC_PATCH_SOURCE the points come from the caller's patch source (patch_source.h); with
// PC_PATCH_SOURCE_GREGORY all 20 points of a Gregory patch are tested, and a point whose NDC
// coordinate is NaN leaves the patch visible (patch_source_cull.cpp's gregory_occluded).
#version 450 core
#include "shared.h"
#include "pass_params.h"
#define PC_CONTROL_POINTS readonly
#define PC_CULL_FLAGS
#define PC_MAX_DISPLACEMENT readonly
#include "patch_buffers.h"
#include "exact_fma.h"
#include "flag_chain.h"
#include "patch_source.h"

layout(local_size_x = kCullGroupSize) in;

#ifdef PC_PATCH_SOURCE
#define PC_PATCH_POINT(p, k) pc_source_points[k]
#define PC_PATCH_POINT_COUNT PC_SOURCE_POINTS
#endif

layout(binding = kTextureUnitHiZ) uniform sampler2D u_hiz;

// frustum_test.h's and hiz_box_test.h's names.
#define u_clip_rows occlusion.clip_rows
#define u_plane_normal_length occlusion.plane_normal_length
#define u_plane_depth occlusion.plane_depth
#define u_screen ivec2(occlusion.screen_width, occlusion.screen_height)
#define u_hiz_levels occlusion.hiz_levels

#include "frustum_test.h"
#include "hiz_box_test.h"

#ifdef PC_PATCH_SOURCE_GREGORY
// True when v is NaN (a test of the bits, which no compiler folds away).
bool pc_is_nan(float v) { return (floatBitsToUint(v) & 0x7FFFFFFFu) > 0x7F800000u; }
#endif

// Steps 2-9 for patch p: true when the patch lies behind the pyramid.
bool hiz_occluded(uint p) {
    HiZPointBox box;
    for (uint k = 0u; k < PC_PATCH_POINT_COUNT; ++k) {
        const vec4 P = PC_PATCH_POINT(p, k);
        // Step 2 (pc_clip_point, frustum_test.h), steps 3-4 (hiz_add_point, hiz_box_test.h).
        const vec4 c = pc_clip_point(P);
        if (!hiz_add_point(P, c, u_clip_rows[3], k == 0u, box)) return false;
#ifdef PC_PATCH_SOURCE_GREGORY
        if (pc_is_nan(hiz_div(c.x, c.w)) || pc_is_nan(hiz_div(c.y, c.w)) || pc_is_nan(hiz_div(c.z, c.w))) return false;
#endif
    }
    return hiz_box_occluded(box.nxmin, box.nxmax, box.nymin, box.nymax, box.zmin);  // steps 5-9
}

// The pass's work on patch p: the frustum test when asked for, then the Hi-Z test.
void pc_occlusion_patch(uint p) {
    const float d = pc_margin(p, occlusion.has_margins);
#ifdef PC_WITH_FRUSTUM
    const bool with_frustum = PC_WITH_FRUSTUM != 0;  // one program each (see PC_MARGINS)
#else
    const bool with_frustum = occlusion.with_frustum != 0u;
#endif
    if (with_frustum) {
        float mx[6];
        if (pc_frustum_culled(p, PC_HAS_MARGINS(occlusion.has_margins), d, false, mx)) {
            pc_chain_cull(p, kCullFrustum);
            return;
        }
    }
    if (d == 0.0 && hiz_occluded(p)) pc_chain_cull(p, kCullOcclusion);
}

void main() {
    const uint p = occlusion.first_patch + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= occlusion.patch_count || pc_chain_culled(p)) return;
#ifdef PC_PATCH_SOURCE
    if (!pc_gather_source(p)) return;
#endif
    PC_RUN_EXACT(p, pc_occlusion_patch(p));
}
