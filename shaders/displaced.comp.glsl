// Displaced-patch cull pass (DisplacedPass, src/gl/displaced_pass.cpp; Niessner & Loop §4.2), one
// invocation per patch: the GPU twin of
// cull_displaced_frustum and cull_displaced_occlusion (include/patchcull/core/displaced_bounds.h,
// src/core/displaced_bounds.cpp). The bound (caf or oobb, u_bound_kind) and its decisions are
// displaced_bounds.h (the GLSL one in shaders/); the cone kind is fixed at compile time by
// PC_DISPLACED_CONE (kDisplacedConeFull 0, kDisplacedConeAcon 1, kDisplacedConeCon 2; the
// culler compiles one program per kind, so the frustum-only full variant does not carry the normal
// patch's 36 cross products; the build validates the con variant, and every function is validated
// whichever kind is picked, since all are defined).
// Per patch: the bound, then the frustum test and, when u_occlusion, hiz.h's steps 5-9 on the
// bound's rectangle (displaced_bound_hiz_decision). A link of the flag chain (flag_chain.h):
// patches culled earlier are skipped, and with only_displaced so are patches whose range is
// (0, 0) (the frustum and occlusion passes test those); a culled patch gets kCullFrustum or
// kCullOcclusion.
#version 450 core
#include "shared.h"
#include "pass_params.h"
#define PC_CONTROL_POINTS readonly
#define PC_CULL_FLAGS
#define PC_MAX_DISPLACEMENT readonly
#include "patch_buffers.h"
#include "exact_fma.h"
#include "backpatch_exact.h"
#define u_zero displaced.zero
#include "backpatch_cones.h"
#include "flag_chain.h"

#ifndef PC_DISPLACED_CONE
#define PC_DISPLACED_CONE 2
#endif

layout(local_size_x = kDisplacedGroupSize) in;

layout(std430, binding = kBindingDisplacementRanges) readonly buffer Ranges {
    vec2 ranges[];  // (d_min, d_max) per patch, read when u_has_ranges
};
layout(std430, binding = kBindingDisplacedBounds) writeonly buffer Bounds {
    float bound_values[];  // kDisplacedBoundValues per patch, written when u_write_bounds
};

// displaced_bounds.h's and hiz_box_test.h's names (pass_params.h's DisplacedParams).
#define u_bound_kind displaced.bound_kind
#define u_object_to_view displaced.object_to_view
#define u_abs_row_z displaced.abs_row_z
#define u_axis_unit displaced.axis_unit
#define u_axis_length displaced.axis_length
#define u_proj displaced.proj
#define u_proj_z displaced.proj_z
#define u_view_planes displaced.view_planes
#define u_delta_slack displaced.constants.x
#define u_ext_scale displaced.constants.y
#define u_frame_pad displaced.constants.z
#define u_depth_safety displaced.constants.w
#define u_screen ivec2(displaced.screen_width, displaced.screen_height)
#define u_hiz_levels displaced.hiz_levels
layout(binding = kTextureUnitHiZ) uniform sampler2D u_hiz;

#include "displaced_bounds.h"
#include "hiz_box_test.h"

/// cone_of: the cone of the compiled kind (none for rational patches).
PcCone pc_displaced_cone(vec4 P[16]) {
    PcCone none;
    none.axis = vec3(0.0);
    none.cos_angle = 0.0;
    none.sin_angle = 1.0;
    none.valid = false;
#if PC_DISPLACED_CONE == 1
    if (pc_is_polynomial(P)) return pc_tangent_cone(P);
#elif PC_DISPLACED_CONE == 2
    if (pc_is_polynomial(P)) return pc_normal_cone(P);
#endif
    return none;
}

/// hiz_decision of displaced_bounds.cpp: frustum, then hiz.h steps 5-9 on a projected bound
/// (hiz_box_test.h, shared with occlusion.comp.glsl).
uint pc_hiz_decision(PcDisplacedBound b) {
    if (pc_bound_outside_frustum(b)) return kPcHiZFrustumCulled;
    if (b.status != kPcBoundProjected) return kPcHiZVisible;
    return hiz_box_occluded(b.ndc_xmin, b.ndc_xmax, b.ndc_ymin, b.ndc_ymax, b.depth_near) ? kPcHiZOccluded
                                                                                          : kPcHiZVisible;
}

void main() {
    const uint p = displaced.first_patch + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= displaced.patch_count || pc_chain_culled(p)) return;
    vec4 P[16];
    for (int k = 0; k < 16; ++k) P[k] = control_points[16u * p + uint(k)];
    const vec2 range = displaced.has_ranges != 0u ? ranges[p] : vec2(0.0);
    const bool has_displacement = range.x != 0.0 || range.y != 0.0;
    if (displaced.only_displaced != 0u && !has_displacement) return;
    PcDisplacedBound bound = pc_invalid_bound();
    if (displaced.view_valid != 0u) {
        // bound_of: nothing to displace, no cone (the bound does not depend on it then).
        PcCone cone;
        cone.axis = vec3(0.0);
        cone.cos_angle = 0.0;
        cone.sin_angle = 1.0;
        cone.valid = false;
        if (has_displacement) cone = pc_displaced_cone(P);
        bound = pc_displaced_bound_with_cone(P, range, cone, u_bound_kind);
    }
    uint reason = 0u;
#ifdef PC_DISPLACED_OCCLUSION
    const bool occlusion = PC_DISPLACED_OCCLUSION != 0;  // one program each (flag_chain.h's PC_MARGINS)
#else
    const bool occlusion = displaced.occlusion != 0u;
#endif
    if (occlusion) {
        const uint decision = pc_hiz_decision(bound);
        reason = decision == kPcHiZFrustumCulled ? kCullFrustum : decision == kPcHiZOccluded ? kCullOcclusion : 0u;
    } else if (pc_bound_outside_frustum(bound)) {
        reason = kCullFrustum;
    }
    if (reason != 0u) pc_chain_cull(p, reason);
    if (displaced.write_bounds != 0u) {
        const uint o = kDisplacedBoundValues * p;
        bound_values[o] = bound.ndc_xmin;
        bound_values[o + 1u] = bound.ndc_xmax;
        bound_values[o + 2u] = bound.ndc_ymin;
        bound_values[o + 3u] = bound.ndc_ymax;
        bound_values[o + 4u] = bound.depth_near;
        bound_values[o + 5u] = bound.depth_far;
        bound_values[o + 6u] = float(bound.status);
        bound_values[o + 7u] = 0.0;
    }
}
