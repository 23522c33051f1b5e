// frustum cull pass, one invocation per patch: the GPU twin of cull_frustum_scalar
// (include/patchcull/frustum.h, src/core/frustum.cpp). Same arithmetic, operation by operation,
// so the decisions are identical (the test itself is shaders/frustum_test.h, shared with
// cull_occlusion.comp.glsl). Writes 0 or kCullFrustum, overwriting the whole flag word.
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

#include "frustum_test.h"

void main() {
    const uint p = gl_GlobalInvocationID.x;
    if (p >= u_patch_count) return;
    const float d = u_has_displacement ? max_displacement[p] : 0.0;
    float mx[6];
    const bool culled = pc_frustum_culled(p, d, mx);
    cull_flags[p] = culled ? kCullFrustum : 0u;
    if (u_write_plane_values)
        for (int q = 0; q < 6; ++q) plane_values[6u * p + uint(q)] = mx[q];
}
