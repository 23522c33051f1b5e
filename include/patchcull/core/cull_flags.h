// patchcull/core/cull_flags.h: the one vocabulary of cull tests and the per-patch flag word, for
// C++ (the kernels, the passes, the tools) and GLSL (the passes' and the engine's shaders) alike.
//
// Valid C++20 and GLSL 4.50 at once: shaders/shared.h includes it, and the shader build
// (cmake/GlShaders.cmake) inlines it there. Constants only, plus (C++ only) the CullTest index.
//
// The flag word: one uint per patch. Bits 0-7 hold the cull reason of the latest frame (0 = not
// culled): the bit of the first test that culled the patch (each pass skips patches whose reason
// is already set). Bits 8-9 hold the temporal status of the two-pass frame of Niessner & Loop,
// "Patch-Based Occlusion Culling for Hardware Tessellation" §3: kStatusVisible = passed the
// latest tests, kStatusNewlyVisible = passed them and was not tagged visible before.
#ifndef PATCHCULL_CORE_CULL_FLAGS_H
#define PATCHCULL_CORE_CULL_FLAGS_H

#ifdef __cplusplus
#include <cstdint>
namespace patchcull {
#define PATCHCULL_FLAG_CONST inline constexpr std::uint32_t
#else
#define PATCHCULL_FLAG_CONST const uint
#endif

PATCHCULL_FLAG_CONST kCullFrustum = 1u;    // outside the view frustum (CullTest::frustum)
PATCHCULL_FLAG_CONST kCullBackPatch = 2u;  // facing away from the eye (CullTest::backpatch)
PATCHCULL_FLAG_CONST kCullOcclusion = 4u;  // behind the Hi-Z pyramid (CullTest::occlusion)
PATCHCULL_FLAG_CONST kCullObject = 8u;     // culled with its object, before any patch test
PATCHCULL_FLAG_CONST kCullReasonMask = 0xFFu;
PATCHCULL_FLAG_CONST kStatusVisible = 0x100u;
PATCHCULL_FLAG_CONST kStatusNewlyVisible = 0x200u;

#ifdef __cplusplus
/// The patch tests, in the order a frame chains them. A test's flag bit is 1 << its index
/// (cull_test_flag); the fused kernel's stages (fused_cull.h) are these tests.
enum class CullTest : std::uint8_t { frustum, backpatch, occlusion };
inline constexpr int kCullTestCount = 3;
inline constexpr CullTest kCullTests[kCullTestCount] = {CullTest::frustum, CullTest::backpatch, CullTest::occlusion};
/// The reason bit a patch culled by `test` gets: kCullFrustum, kCullBackPatch or kCullOcclusion.
constexpr std::uint32_t cull_test_flag(CullTest test) { return 1u << static_cast<unsigned>(test); }
/// "frustum", "backpatch", "occlusion".
constexpr const char* cull_test_name(CullTest test) {
    return test == CullTest::frustum ? "frustum" : test == CullTest::backpatch ? "backpatch" : "occlusion";
}
static_assert(cull_test_flag(CullTest::frustum) == kCullFrustum &&
              cull_test_flag(CullTest::backpatch) == kCullBackPatch &&
              cull_test_flag(CullTest::occlusion) == kCullOcclusion);
}  // namespace patchcull
#endif
#undef PATCHCULL_FLAG_CONST

#endif  // PATCHCULL_CORE_CULL_FLAGS_H
