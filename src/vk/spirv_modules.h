// The passes' SPIR-V modules, compiled from shaders/*.comp.glsl at build time and embedded
// (src/vk/CMakeLists.txt generates spirv_table.cpp in the build tree). Not a public header.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace patchcull::vk::detail {

struct SpirvModule {
    const char* shader;          ///< the GLSL source's name, e.g. "frustum.comp.glsl"
    const char* variant;         ///< the define of its variant (e.g. "PATCHCULL_NCONE"), or ""
    bool fma_via_double;         ///< compiled with PATCHCULL_FMA_VIA_DOUBLE
    const std::uint32_t* words;  ///< the module
    std::size_t word_count;
};

extern const SpirvModule kSpirvModules[];
extern const std::size_t kSpirvModuleCount;

/// The module of shader in that variant ("" for the plain one) and fma mode, or nullptr.
inline const SpirvModule* find_spirv_module(std::string_view shader, std::string_view variant, bool fma_via_double) {
    for (std::size_t i = 0; i < kSpirvModuleCount; ++i)
        if (shader == kSpirvModules[i].shader && variant == kSpirvModules[i].variant &&
            kSpirvModules[i].fma_via_double == fma_via_double)
            return &kSpirvModules[i];
    return nullptr;
}

}  // namespace patchcull::vk::detail
