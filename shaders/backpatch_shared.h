// shaders/backpatch_shared.h: constants shared by the GPU back-patch culler
// (include/patchcull/gl/gl_backpatch.h, src/gl/backpatch_culler.cpp) and its compute shaders
// (backpatch_cones, backpatch_ptp, backpatch_probe). Valid C++20 and GLSL 4.50 at once, like
// shared.h (whose buffer bindings the culler uses for the control points and the flag words:
// kBindingControlPoints and kBindingCullFlags). Only `const uint` constants.
#ifndef PATCHCULL_SHADERS_BACKPATCH_SHARED_H
#define PATCHCULL_SHADERS_BACKPATCH_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace patchcull::gl::backpatch_shared {
using uint = std::uint32_t;
#define PATCHCULL_BP_CONST inline constexpr
#else
#define PATCHCULL_BP_CONST const
#endif

// Buffers (binding points in shared.h): the diagnostics of backpatch_ptp at kBindingPtpPlanes
// (std430 float t[64 * patch_count]: patch p's control plane z components at 64p + 8 jv + iu,
// exactly the CPU kernel's t), written only on request; the diagnostics of backpatch_cones (tcone
// / ncone) at kBindingConeValues (std430 float c[kConeValues * patch_count]: patch p's cone and
// sphere at kConeValues p + (axis.x, axis.y, axis.z, cos, sin, valid (1 or 0), center.x, center.y,
// center.z, radius, 0, 0)), written only on request; the input and output of
// backpatch_probe.comp.glsl (tests and the start-up fma check) at kBindingProbeIn / Out.
PATCHCULL_BP_CONST uint kConeValues = 12u;

// Work groups: cones, one invocation per patch; ptp, kPtpLanes invocations per patch (Loop, Niessner &
// Eisenacher §6: 16 threads per patch, each owning one 4x4 block's 4 destinations) and kPtpPatchesPerGroup
// patches per work group (local size kPtpLanes x kPtpPatchesPerGroup).
PATCHCULL_BP_CONST uint kConeGroupSize = 64u;
PATCHCULL_BP_CONST uint kPtpLanes = 16u;
PATCHCULL_BP_CONST uint kPtpPatchesPerGroup = 8u;
PATCHCULL_BP_CONST uint kProbeGroupSize = 64u;

// backpatch_probe modes (u_mode).
PATCHCULL_BP_CONST uint kProbeFma = 0u;   // out = pc_fma(a, b, c)
PATCHCULL_BP_CONST uint kProbeDiv = 1u;   // out = pc_div(a, b)
PATCHCULL_BP_CONST uint kProbeSqrt = 2u;  // out = pc_sqrt(a)
PATCHCULL_BP_CONST uint kProbeDivFrom = 3u;   // out = pc_div_from(a, b, c): c a guess of a / b
PATCHCULL_BP_CONST uint kProbeSqrtFrom = 4u;  // out = pc_sqrt_from(a, b): b a guess of sqrt(a)

#ifdef __cplusplus
}  // namespace patchcull::gl::backpatch_shared
#endif
#undef PATCHCULL_BP_CONST

#endif  // PATCHCULL_SHADERS_BACKPATCH_SHARED_H
