// shaders/shared.h: constants shared by the C++ renderer (src/gl) and the GLSL shaders.
//
// Valid C++20 and GLSL 4.50 at once. Shaders pull it in with `#include "shared.h"`, which the
// build replaces by this file's text (cmake/GlShaders.cmake) before validating the expanded
// shader with glslangValidator and embedding it into the binary; C++ includes it directly.
// Only `const uint` constants live here: they are the contract between the two languages
// (buffer binding points, flag bits, work-group sizes, id encoding).
#ifndef PATCHCULL_SHADERS_SHARED_H
#define PATCHCULL_SHADERS_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace patchcull::gl::shared {
using uint = std::uint32_t;
#define PATCHCULL_CONST inline constexpr
#else
#define PATCHCULL_CONST const
#endif

// Shader storage buffer binding points (std430).
PATCHCULL_CONST uint kBindingControlPoints = 0u;  // vec4 cp[16 * patch_count]: patch p's point k at 16p+k
PATCHCULL_CONST uint kBindingCullFlags = 1u;      // uint flags[patch_count]: 0 = draw, nonzero = culled
PATCHCULL_CONST uint kBindingMaxDisplacement = 2u; // float max_disp[patch_count], >= 0 (cull margin)
PATCHCULL_CONST uint kBindingPatchTexcoords = 3u;  // vec2 uv[4 * patch_count]: corner texcoords (patch.h order)
PATCHCULL_CONST uint kBindingPlaneValues = 4u;     // float values[6 * patch_count]: frustum diagnostics

// Texture units.
PATCHCULL_CONST uint kTextureUnitDisplacement = 0u;  // R32F height map, GL_REPEAT, bilinear

// Cull flag bits. Each cull pass ORs its bit in (the frustum pass, the first, overwrites).
PATCHCULL_CONST uint kCullFrustum = 1u;
PATCHCULL_CONST uint kCullBackPatch = 2u;   // reserved for the back-patch pass
PATCHCULL_CONST uint kCullOcclusion = 4u;   // reserved for the Hi-Z occlusion pass

// Patch-ID buffer encoding (R32UI): 0 = background, patch p writes p + 1. Ids with the top bit
// set are reserved for triangle-mesh occluders (not drawn yet).
PATCHCULL_CONST uint kIdBackground = 0u;
PATCHCULL_CONST uint kIdOccluderBit = 0x80000000u;

// Compute work-group size of the per-patch cull shaders (one invocation per patch).
PATCHCULL_CONST uint kCullGroupSize = 64u;

#ifdef __cplusplus
}  // namespace patchcull::gl::shared
#endif
#undef PATCHCULL_CONST

#endif  // PATCHCULL_SHADERS_SHARED_H
