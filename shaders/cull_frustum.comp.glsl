// frustum cull pass, one invocation per patch: the GPU twin of cull_frustum_scalar
// (include/patchcull/frustum.h, src/core/frustum.cpp). Same arithmetic, operation by operation,
// so the decisions are identical: for each clip plane q with row r and margin
//   c = fma(D, |r.xyz|, r.w),
// value_k = fma(c, W, fma(r.z, Z, fma(r.y, Y, r.x * X))) for control point k = (X, Y, Z, W), the
// patch is culled when the maximum over the 16 points is < 0 for some plane. `precise` keeps the
// compiler from contracting or reassociating; max is written as the CPU's `a > b ? a : b`; pc_fma
// is exactly rounded also on llvmpipe (exact_fma.h).
#version 450 core
#include "shared.h"
#include "exact_fma.h"

layout(local_size_x = kCullGroupSize) in;

layout(std430, binding = kBindingControlPoints) readonly buffer ControlPoints {
    vec4 control_points[];
};
layout(std430, binding = kBindingCullFlags) writeonly buffer CullFlags {
    uint cull_flags[];
};
layout(std430, binding = kBindingMaxDisplacement) readonly buffer MaxDisplacement {
    float max_displacement[];
};
layout(std430, binding = kBindingPlaneValues) writeonly buffer PlaneValues {
    float plane_values[];  // 6 per patch, written only when u_write_plane_values
};

uniform vec4 u_plane_rows[6];         // FrustumPlanes::rows
uniform float u_plane_normal_length[6];  // FrustumPlanes::normal_length
uniform uint u_patch_count;
uniform bool u_has_displacement;
uniform bool u_write_plane_values;

void main() {
    const uint p = gl_GlobalInvocationID.x;
    if (p >= u_patch_count) return;
    const float d = u_has_displacement ? max_displacement[p] : 0.0;

    precise float c[6];
    precise float mx[6];
    for (int q = 0; q < 6; ++q) {
        c[q] = pc_fma(d, u_plane_normal_length[q], u_plane_rows[q].w);
        mx[q] = uintBitsToFloat(0xFF800000u);  // -infinity
    }
    for (uint k = 0u; k < 16u; ++k) {
        const vec4 point = control_points[16u * p + k];
        for (int q = 0; q < 6; ++q) {
            const vec4 r = u_plane_rows[q];
            precise float value = r.x * point.x;
            value = pc_fma(r.y, point.y, value);
            value = pc_fma(r.z, point.z, value);
            value = pc_fma(c[q], point.w, value);
            mx[q] = mx[q] > value ? mx[q] : value;
        }
    }
    bool culled = false;
    for (int q = 0; q < 6; ++q) culled = culled || mx[q] < 0.0;
    cull_flags[p] = culled ? kCullFrustum : 0u;
    if (u_write_plane_values)
        for (int q = 0; q < 6; ++q) plane_values[6u * p + uint(q)] = mx[q];
}
