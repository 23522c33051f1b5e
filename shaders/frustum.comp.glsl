// Frustum cull pass (FrustumPass, src/gl/frustum_pass.cpp), one invocation per patch: the GPU twin
// of cull_frustum_scalar (include/patchcull/core/frustum.h, src/core/frustum.cpp). Same arithmetic,
// operation by operation, so the decisions are identical (the test itself is shaders/frustum_test.h,
// shared with occlusion.comp.glsl; without plane values it stops at the point that settles the
// verdict, which is then the same). A link of the flag chain (gl_passes.h): a patch that an earlier
// pass of the frame culled is left as it is; otherwise a culled patch gets the reason kCullFrustum.
// With PC_PATCH_SOURCE the points come from the caller's patch source (patch_source.h: Bezier or
// converted B-spline points, or with PC_PATCH_SOURCE_GREGORY a Gregory patch's 20 points, all
// tested as cull_frustum over a PatchSourceView tests them).
#version 450 core
#include "shared.h"
#include "pass_params.h"
#define PC_CONTROL_POINTS readonly
#define PC_CULL_FLAGS
#define PC_MAX_DISPLACEMENT readonly
#define PC_PLANE_VALUES writeonly  // written only when write_plane_values
#include "patch_buffers.h"
#include "exact_fma.h"
#include "flag_chain.h"
#include "patch_source.h"

layout(local_size_x = kCullGroupSize) in;

#ifdef PC_PATCH_SOURCE
#define PC_PATCH_POINT(p, k) pc_source_points[k]
#define PC_PATCH_POINT_COUNT PC_SOURCE_POINTS
#endif

// frustum_test.h's names.
#define u_clip_rows frustum.clip_rows
#define u_plane_normal_length frustum.plane_normal_length
#define u_plane_depth frustum.plane_depth
#include "frustum_test.h"

// The pass's work on patch p: its frustum decision, and its plane values when asked for.
void pc_frustum_patch(uint p) {
    const float d = pc_margin(p, frustum.has_margins);
    float mx[6];
    const bool want_maxima = frustum.write_plane_values != 0u;
    if (pc_frustum_culled(p, PC_HAS_MARGINS(frustum.has_margins), d, want_maxima, mx))
        pc_chain_cull(p, kCullFrustum);
    if (want_maxima)
        for (int q = 0; q < 6; ++q) plane_values[6u * p + uint(q)] = mx[q];
}

void main() {
    const uint p = frustum.first_patch + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= frustum.patch_count || pc_chain_culled(p)) return;
#ifdef PC_PATCH_SOURCE
    if (!pc_gather_source(p)) return;
#endif
    PC_RUN_EXACT(p, pc_frustum_patch(p));
}
