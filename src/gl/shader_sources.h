// The shaders of shaders/*.glsl, expanded and embedded at build time (cmake/GlShaders.cmake
// generates shader_sources_embedded.cpp in the build tree).
#pragma once

#include <cstddef>
#include <string_view>

namespace patchcull::gl::detail {

struct ShaderSource {
    const char* name;  ///< file name, e.g. "patch.tesc.glsl"
    const char* text;  ///< GLSL with shaders/shared.h inlined
};

extern const ShaderSource kShaderSources[];
extern const std::size_t kShaderSourceCount;

/// The embedded shader named name, or nullptr.
inline const char* find_shader_source(std::string_view name) {
    for (std::size_t i = 0; i < kShaderSourceCount; ++i)
        if (name == kShaderSources[i].name) return kShaderSources[i].text;
    return nullptr;
}

}  // namespace patchcull::gl::detail
