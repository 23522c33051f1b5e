// Displaced-patch cull pass (seed 000 §4.2), one invocation per patch: the GPU twin of
// cull_displaced_frustum and cull_displaced_occlusion (include/patchcull/displaced_bounds.h,
// src/core/displaced_bounds.cpp). The bound (caf or oobb, u_bound_kind) and its decisions are
// displaced_bounds.h (the GLSL one in shaders/); the cone kind is fixed at compile time by
// PC_DISPLACED_CONE (kDisplacedConeFull 0, kDisplacedConeAcon 1, kDisplacedConeCon 2; the
// culler compiles one program per kind, so the frustum-only full variant does not carry the normal
// patch's 36 cross products; the build validates the con variant, and every function is validated
// whichever kind is picked, since all are defined).
// Per patch: the bound, then the frustum test and, when u_occlusion, hiz.h's steps 5-9 on the
// bound's rectangle (displaced_bound_hiz_decision). Writes the flag word (kBindingCullFlags):
// kCullFrustum, kCullOcclusion or 0, the renderer's reason bits (status bits 0).
#version 450 core
#include "shared.h"
#include "displaced_shared.h"
#include "backpatch_shared.h"
#include "exact_fma.h"
#include "backpatch_exact.h"
#include "backpatch_cones.h"

#ifndef PC_DISPLACED_CONE
#define PC_DISPLACED_CONE 2
#endif

layout(local_size_x = kDisplacedGroupSize) in;

layout(std430, binding = kBindingControlPoints) readonly buffer ControlPoints {
    vec4 control_points[];  // patch p's point k at 16p + k (patch.h order)
};
layout(std430, binding = kBindingCullFlags) writeonly buffer CullFlags {
    uint cull_flags[];
};
layout(std430, binding = kBindingDisplacementRanges) readonly buffer Ranges {
    vec2 ranges[];  // (d_min, d_max) per patch, read when u_has_ranges
};
layout(std430, binding = kBindingDisplacedBounds) writeonly buffer Bounds {
    float bound_values[];  // kDisplacedBoundValues per patch, written when u_write_bounds
};

uniform uint u_patch_count;
uniform uint u_first_patch;  // dispatches cover patches from here (large sets take several)
uniform bool u_has_ranges;
uniform bool u_write_bounds;
uniform uint u_bound_kind;   // kDisplacedBoundOobb or kDisplacedBoundCaf
uniform bool u_occlusion;    // also the Hi-Z test (else frustum only)
uniform bool u_view_valid;   // DisplacedCullView::valid: false = every bound invalid, nothing culled

// DisplacedCullView.
uniform mat4 u_object_to_view;  // column-major: u_object_to_view[c][r] = V(r, c)
uniform vec4 u_abs_row_z;       // |V(2, c)|
uniform vec3 u_axis_unit[3];
uniform float u_axis_length[3];
uniform vec4 u_proj;            // P00, P02, P11, P12
uniform vec2 u_proj_z;          // P22, P23
uniform vec4 u_view_planes[6];  // make_frustum_planes(projection).rows

// displaced_bounds.h's constants, from the C++ values.
uniform float u_delta_slack;    // kDisplacedDeltaSlack
uniform float u_ext_scale;      // kDisplacedExtScale
uniform float u_frame_pad;      // kDisplacedFramePad
uniform float u_depth_safety;   // kDisplacedDepthSafety

// Hi-Z pyramid of a W x H depth buffer (hiz.h's levels in the lower-left part of each mip level).
uniform ivec2 u_screen;
uniform int u_hiz_levels;
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
/// (hiz_box_test.h, shared with cull_occlusion.comp.glsl).
uint pc_hiz_decision(PcDisplacedBound b) {
    if (pc_bound_outside_frustum(b)) return kPcHiZFrustumCulled;
    if (b.status != kPcBoundProjected) return kPcHiZVisible;
    return hiz_box_occluded(b.ndc_xmin, b.ndc_xmax, b.ndc_ymin, b.ndc_ymax, b.depth_near) ? kPcHiZOccluded
                                                                                          : kPcHiZVisible;
}

void main() {
    const uint p = u_first_patch + gl_GlobalInvocationID.x;
    if (p >= u_patch_count) return;
    vec4 P[16];
    for (int k = 0; k < 16; ++k) P[k] = control_points[16u * p + uint(k)];
    const vec2 range = u_has_ranges ? ranges[p] : vec2(0.0);
    PcDisplacedBound bound = pc_invalid_bound();
    if (u_view_valid) {
        // bound_of: nothing to displace, no cone (the bound does not depend on it then).
        const bool displaced = range.x != 0.0 || range.y != 0.0;
        PcCone cone;
        cone.axis = vec3(0.0);
        cone.cos_angle = 0.0;
        cone.sin_angle = 1.0;
        cone.valid = false;
        if (displaced) cone = pc_displaced_cone(P);
        bound = pc_displaced_bound_with_cone(P, range, cone, u_bound_kind);
    }
    uint word = 0u;
    if (u_occlusion) {
        const uint decision = pc_hiz_decision(bound);
        word = decision == kPcHiZFrustumCulled ? kCullFrustum : decision == kPcHiZOccluded ? kCullOcclusion : 0u;
    } else if (pc_bound_outside_frustum(bound)) {
        word = kCullFrustum;
    }
    cull_flags[p] = word;
    if (u_write_bounds) {
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
