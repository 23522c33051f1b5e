// shaders/displaced_shared.h: constants shared by the GPU displaced-patch culler
// (include/patchcull/gl/gl_displaced.h, src/gl/displaced_culler.cpp) and its compute shader
// (displaced.comp.glsl). Valid C++20 and GLSL 4.50 at once, like shared.h, whose bindings the
// culler uses for the control points (kBindingControlPoints) and the flag words (kBindingCullFlags),
// and whose texture unit kTextureUnitHiZ holds the Hi-Z pyramid. Only `const uint` constants.
#ifndef PATCHCULL_SHADERS_DISPLACED_SHARED_H
#define PATCHCULL_SHADERS_DISPLACED_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace patchcull::gl::displaced_shared {
using uint = std::uint32_t;
#define PATCHCULL_DS_CONST inline constexpr
#else
#define PATCHCULL_DS_CONST const
#endif

// Buffers (binding points in shared.h): per-patch displacement ranges at
// kBindingDisplacementRanges (std430 vec2 range[patch_count]: (d_min, d_max)), read only when the
// culler has ranges (else every patch is undisplaced, as a null ranges pointer on the CPU);
// diagnostics at kBindingDisplacedBounds (std430 float b[kDisplacedBoundValues * patch_count]):
// patch p's DisplacedBound at kDisplacedBoundValues p + (ndc_xmin, ndc_xmax, ndc_ymin, ndc_ymax,
// depth_near, depth_far, status as a float, 0), written only on request.
PATCHCULL_DS_CONST uint kDisplacedBoundValues = 8u;

// One invocation per patch.
PATCHCULL_DS_CONST uint kDisplacedGroupSize = 64u;

// u_bound_kind (DisplacedBoundKind) and the PC_DISPLACED_CONE compile-time define (NormalConeKind).
PATCHCULL_DS_CONST uint kDisplacedBoundOobb = 0u;
PATCHCULL_DS_CONST uint kDisplacedBoundCaf = 1u;
PATCHCULL_DS_CONST uint kDisplacedConeFull = 0u;
PATCHCULL_DS_CONST uint kDisplacedConeAcon = 1u;
PATCHCULL_DS_CONST uint kDisplacedConeCon = 2u;

#ifdef __cplusplus
}  // namespace patchcull::gl::displaced_shared
#endif
#undef PATCHCULL_DS_CONST

#endif  // PATCHCULL_SHADERS_DISPLACED_SHARED_H
