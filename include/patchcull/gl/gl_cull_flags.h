// patchcull/gl/gl_cull_flags.h: the per-patch flag word of library patchcull_gl, the occluder id
// bit, patch and triangle spans, and the cull modes (their names for the tools).
//
// - Flag word: one uint per patch (PatchRenderer::flag_buffer(), gl_renderer.h), read by the TCS
//   (shaders/patchcull_tcs.h). Bits 0-7 = cull reason of the latest frame, 0 = not culled:
//   kFlagFrustum (1), kFlagBackPatch (2), kFlagOcclusion (4) (shaders/shared.h). Bits 8-9 =
//   temporal status of the pipeline: kStatusVisible (passed the latest tests) and
//   kStatusNewlyVisible (passed them, and was not tagged visible before); gl_passes.h's flag chain
//   writes both. A culled patch gets tessellation levels 0 in the TCS and is discarded by the
//   tessellator (Niessner & Loop §3, Sathe: cull in the patch-constant phase).
// - Id buffer: triangle t of the occluder mesh writes kIdOccluderBit | t (patches write their
//   index + 1, background 0; gl_renderer.h).
#pragma once

#include <cstddef>
#include <cstdint>

namespace patchcull::gl {

// Flag word bits and id encoding (equal to shaders/shared.h's; static_asserts in the renderer).
inline constexpr std::uint32_t kFlagFrustum = 1u;        ///< culled by the view frustum
inline constexpr std::uint32_t kFlagBackPatch = 2u;      ///< culled as back-facing (a back-patch pass)
inline constexpr std::uint32_t kFlagOcclusion = 4u;      ///< culled behind the Hi-Z pyramid
inline constexpr std::uint32_t kFlagObject = 8u;         ///< culled with its object (object_culling.h)
inline constexpr std::uint32_t kFlagReasonMask = 0xFFu;  ///< bits of the cull reason
inline constexpr std::uint32_t kStatusVisible = 0x100u;  ///< passed the latest test
inline constexpr std::uint32_t kStatusNewlyVisible = 0x200u;  ///< ... and was not tagged visible
inline constexpr std::uint32_t kIdOccluderBit = 0x80000000u;  ///< id of occluder triangle t: bit | t

/// Patches [first, first + count) of the set (object-level culling and draws restricted to spans).
struct PatchSpan {
    std::size_t first = 0;
    std::size_t count = 0;
};
/// Occluder triangles [first, first + count) (set_occluders' triangle order).
struct TriangleSpan {
    std::size_t first = 0;
    std::size_t count = 0;
};

/// Which tests a frame runs (CullPipeline, gl_pipeline.h); the values are the flag bits a culled
/// patch gets.
enum class CullMode : std::uint32_t {
    none = 0,
    frustum = kFlagFrustum,
    backpatch = kFlagBackPatch,
    occlusion = kFlagOcclusion,
    all = kFlagFrustum | kFlagBackPatch | kFlagOcclusion,
};
/// Every cull mode, in the order the tools list them (render's and view's --cull).
inline constexpr CullMode kCullModes[] = {CullMode::none, CullMode::frustum, CullMode::backpatch, CullMode::occlusion,
                                          CullMode::all};
/// "none", "frustum", "backpatch", "occlusion", "all".
const char* cull_mode_name(CullMode mode);
/// Parses cull_mode_name's names; returns false (mode unchanged) otherwise.
bool parse_cull_mode(const char* text, CullMode& mode);

}  // namespace patchcull::gl
