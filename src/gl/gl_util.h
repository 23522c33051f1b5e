// GL helpers shared by the renderer and the passes (not a public header): error checks, shader
// compilation from the embedded sources (shader_sources.h), buffer uploads and checks.
#pragma once

#include <epoxy/gl.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/core/patch.h"
#include "shader_sources.h"

namespace patchcull::gl {

namespace detail {

inline std::string hex(unsigned value) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", value);
    return buf;
}

inline void check_gl(const char* where) {
    const GLenum e = glGetError();
    if (e == GL_NO_ERROR) return;
    while (glGetError() != GL_NO_ERROR) {
    }
    throw Error("GL: error " + hex(e) + " after " + where);
}

// The first line of a driver's info log (which may end in NUL padding), "(...)" when more follow.
inline std::string first_line(std::string log) {
    log.resize(std::min(log.find('\0'), log.size()));
    while (!log.empty() && (log.back() == '\n' || log.back() == '\r' || log.back() == ' ')) log.pop_back();
    const std::size_t nl = log.find('\n');
    if (nl != std::string::npos) log = log.substr(0, nl) + " (...)";
    return log;
}

// Compiles embedded shader name with `defines` (lines "#define X 1\n") inserted after #version.
inline GLuint compile_shader(const char* name, GLenum stage, const std::string& defines) {
    const char* embedded = detail::find_shader_source(name);
    if (!embedded) throw Error(std::string("GL: shader ") + name + " is not embedded");
    std::string text = embedded;
    const std::size_t version = text.find("#version");
    if (version == std::string::npos) throw Error(std::string("GL: shader ") + name + " has no #version line");
    const std::size_t line_end = text.find('\n', version);
    text.insert(line_end == std::string::npos ? text.size() : line_end + 1, defines);
    const char* source = text.c_str();
    const GLuint s = glCreateShader(stage);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetShaderiv(s, GL_INFO_LOG_LENGTH, &len);
        std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
        glGetShaderInfoLog(s, len, nullptr, log.data());
        glDeleteShader(s);
        throw Error(std::string("GL: shader ") + name + ": " + first_line(std::move(log)));
    }
    return s;
}

inline GLuint link_program(const std::vector<std::pair<const char*, GLenum>>& stages, const char* label,
                           const std::string& defines = {}) {
    const GLuint program = glCreateProgram();
    std::vector<GLuint> shaders;
    try {
        for (const auto& [name, stage] : stages) shaders.push_back(compile_shader(name, stage, defines));
    } catch (...) {
        for (GLuint s : shaders) glDeleteShader(s);
        glDeleteProgram(program);
        throw;
    }
    for (GLuint s : shaders) glAttachShader(program, s);
    glLinkProgram(program);
    for (GLuint s : shaders) {
        glDetachShader(program, s);
        glDeleteShader(s);
    }
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetProgramiv(program, GL_INFO_LOG_LENGTH, &len);
        std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
        glGetProgramInfoLog(program, len, nullptr, log.data());
        glDeleteProgram(program);
        throw Error(std::string("GL: program ") + label + ": " + first_line(std::move(log)));
    }
    return program;
}

// (Re)allocates buffer with size bytes (at least 16: a zero-sized store cannot be bound).
inline void upload(GLuint buffer, std::size_t size, const void* data) {
    glNamedBufferData(buffer, static_cast<GLsizeiptr>(std::max<std::size_t>(size, 16)), nullptr, GL_DYNAMIC_DRAW);
    if (size && data) glNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(size), data);
}

// Uploads a structure-of-arrays batch as the GPU passes' control-point layout (16 vec4 per patch,
// patch.h order) into buffer.
inline void upload_patch_batch(GLuint buffer, const PatchBatchView& patches) {
    std::vector<float> aos(patches.count * kPatchPoints * 4);
    for (std::size_t p = 0; p < patches.count; ++p)
        for (int k = 0; k < kPatchPoints; ++k)
            for (int c = 0; c < 4; ++c) aos[(p * kPatchPoints + k) * 4 + c] = patches.component(k, c)[p];
    upload(buffer, aos.size() * sizeof(float), aos.data());
}

// Throws (a one-line message starting with `who`) unless buffer is a GL buffer holding at least
// count patches in that layout (a caller's control points read in place by a cull pass).
inline void check_patch_buffer(const std::string& who, std::uint32_t buffer, std::size_t count) {
    if (!glIsBuffer(buffer)) throw Error("GL: " + who + ": " + std::to_string(buffer) + " is not a buffer");
    GLint64 size = 0;
    glGetNamedBufferParameteri64v(buffer, GL_BUFFER_SIZE, &size);
    if (static_cast<std::uint64_t>(size) < count * sizeof(BezierPatch))
        throw Error("GL: " + who + ": buffer of " + std::to_string(size) + " bytes for " + std::to_string(count) +
                    " patches");
}

template <class T>
std::vector<T> flip_rows(const std::vector<T>& in, int width, int height, int per_pixel) {
    std::vector<T> out(in.size());
    const std::size_t row = static_cast<std::size_t>(width) * per_pixel;
    for (int y = 0; y < height; ++y)
        std::copy_n(in.begin() + static_cast<std::ptrdiff_t>(row * (height - 1 - y)), row,
                    out.begin() + static_cast<std::ptrdiff_t>(row * y));
    return out;
}

}  // namespace detail

}  // namespace patchcull::gl
