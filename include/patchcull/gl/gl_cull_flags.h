// patchcull/gl/gl_cull_flags.h: the per-patch flag word of library patchcull_gl, the occluder id
// bit, patch and triangle spans, and the cull modes (their names for the tools).
//
// - Flag word: one uint per patch (PatchRenderer::flag_buffer(), gl_renderer.h), read by the TCS
//   (shaders/patchcull_tcs.h). Bits 0-7 = cull reason of the latest frame, 0 = not culled:
//   kCullFrustum (1), kCullBackPatch (2), kCullOcclusion (4), kCullObject (8)
//   (core/cull_flags.h). Bits 8-9 =
//   temporal status of the pipeline: kStatusVisible (passed the latest tests) and
//   kStatusNewlyVisible (passed them, and was not tagged visible before); gl_passes.h's flag chain
//   writes both. A culled patch gets tessellation levels 0 in the TCS and is discarded by the
//   tessellator (Niessner & Loop §3, Sathe: cull in the patch-constant phase).
// - Id buffer: triangle t of the occluder mesh writes kIdOccluderBit | t (patches write their
//   index + 1, background 0; gl_renderer.h).
#pragma once

#include <cstddef>
#include <cstdint>

#include "patchcull/core/cull_flags.h"
#include "patchcull/core/patch_runs.h"

namespace patchcull::gl {

// The flag word's bits are core/cull_flags.h's (one vocabulary for C++ and GLSL); gl:: names them
// too, for code written against this layer.
using patchcull::kCullBackPatch;
using patchcull::kCullFrustum;
using patchcull::kCullObject;
using patchcull::kCullOcclusion;
using patchcull::kCullReasonMask;
using patchcull::kStatusNewlyVisible;
using patchcull::kStatusVisible;
/// Id of occluder triangle t in the id buffer: kIdOccluderBit | t (shaders/shared.h's value).
inline constexpr std::uint32_t kIdOccluderBit = 0x80000000u;

/// Patches [first, first + count) of the set (object-level culling and draws restricted to spans):
/// core/patch_runs.h's.
using patchcull::PatchSpan;
/// Occluder triangles [first, first + count) (set_occluders' triangle order).
struct TriangleSpan {
    std::size_t first = 0;
    std::size_t count = 0;
};

/// Which tests a frame runs (CullPipeline, gl_pipeline.h); the values are the flag bits a culled
/// patch gets.
enum class CullMode : std::uint32_t {
    none = 0,
    frustum = kCullFrustum,
    backpatch = kCullBackPatch,
    occlusion = kCullOcclusion,
    all = kCullFrustum | kCullBackPatch | kCullOcclusion,
};
/// Every cull mode, in the order the tools list them (render's and view's --cull).
inline constexpr CullMode kCullModes[] = {CullMode::none, CullMode::frustum, CullMode::backpatch, CullMode::occlusion,
                                          CullMode::all};
/// "none", "frustum", "backpatch", "occlusion", "all".
const char* cull_mode_name(CullMode mode);
/// Parses cull_mode_name's names; returns false (mode unchanged) otherwise.
bool parse_cull_mode(const char* text, CullMode& mode);

}  // namespace patchcull::gl
