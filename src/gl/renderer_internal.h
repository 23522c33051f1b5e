// Internals of PatchRenderer (patchcull/gl_renderer.h) shared by the renderer's sources:
// patch_renderer.cpp (buffers, programs, drawing, the frustum pass, read-backs) and
// occlusion_pipeline.cpp (Hi-Z build, the combined cull pass, render_frame, the status image).
// Not a public header.
#pragma once

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "patchcull/error.h"
#include "patchcull/gl_renderer.h"
#include "patchcull/hiz.h"
#include "png_file.h"
#include "shader_sources.h"
#include "shared.h"

namespace patchcull::gl {

namespace sh = shared;

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

inline std::string first_line(std::string log) {
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
        throw Error(std::string("GL: shader ") + name + ": " + first_line(log.c_str()));
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
        throw Error(std::string("GL: program ") + label + ": " + first_line(log.c_str()));
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

using namespace detail;

struct PatchRenderer::Impl {
    GLuint vao = 0;
    GLuint mark_program = 0;  // the patch program with PATCHCULL_MARK_FRONT (patch.frag.glsl)
    GLuint draw_program = 0, frustum_program = 0, occlusion_program = 0, hiz_program = 0, occluder_program = 0;
    GLuint control_points = 0, cull_flags = 0, max_displacement = 0, texcoords = 0, plane_values = 0;
    GLuint backpatch_flags = 0, counters = 0, occluder_vertices = 0, tangents = 0;
    GLuint drawn_marks = 0, front_marks = 0;  // uint per patch at kBindingPatchMarks (shared.h)
    GLuint tess_scale = 0;                    // float per patch at kBindingPatchTessScale
    float max_tess_scale = 1;                 // largest entry of tess_scale (the draw split)
    GLuint displacement_texture = 0;
    float displacement_scale = 0, displacement_midlevel = 0.5f;
    bool has_displacement_map = false;
    bool has_max_displacement = false;
    bool has_tangents = false;  // the tangent buffer holds kTangentVec4s vec4 per patch
    bool fma_via_double = false;
    bool is_software = false;
    GLuint fbo = 0, color = 0, ids = 0, depth = 0;
    int width = 0, height = 0;
    std::size_t count = 0;
    std::size_t occluder_triangles = 0;
    // Hi-Z pyramid: a POT R32F mipmapped texture (level l allocated >= W_l x H_l, hiz.h's sizes
    // used), built for hiz_width x hiz_height; the layout of hiz.h in hiz_layout.
    GLuint hiz = 0;
    int hiz_width = 0, hiz_height = 0;
    std::vector<HiZLevel> hiz_layout;
    // Status visualisation: its own colour + depth framebuffer.
    GLuint vis_fbo = 0, vis_color = 0, vis_depth = 0;
    int vis_width = 0, vis_height = 0;
    GLuint timer_queries[5] = {};
    bool primed = false;  // statuses valid for the pipeline (else the next frame tags even patches)

    // Uniform locations of a patch program (draw_program, mark_program).
    struct DrawUniforms {
        GLint tess_level, draw_mask, draw_value, adaptive, tess_reference, object_to_clip, displace,
            displacement_scale, displacement_midlevel, eye, color_mode, has_tangents, mark_drawn,
            discard_back_facing;
        void locate(GLuint p) {
            *this = {glGetUniformLocation(p, "u_tess_level"),         glGetUniformLocation(p, "u_draw_mask"),
                     glGetUniformLocation(p, "u_draw_value"),         glGetUniformLocation(p, "u_adaptive"),
                     glGetUniformLocation(p, "u_tess_reference"),     glGetUniformLocation(p, "u_object_to_clip"),
                     glGetUniformLocation(p, "u_displace"),           glGetUniformLocation(p, "u_displacement_scale"),
                     glGetUniformLocation(p, "u_displacement_midlevel"), glGetUniformLocation(p, "u_eye"),
                     glGetUniformLocation(p, "u_color_mode"),         glGetUniformLocation(p, "u_has_tangents"),
                     glGetUniformLocation(p, "u_mark_drawn"),         glGetUniformLocation(p, "u_discard_back_facing")};
        }
    };
    DrawUniforms draw_loc{}, mark_loc{};
    struct {
        GLint rows, normal_length, patch_count, has_displacement, write_plane_values;
    } frustum_loc{};
    struct {
        GLint rows, normal_length, patch_count, has_displacement, has_backpatch, tests, object_to_clip, screen,
            hiz_levels;
    } occlusion_loc{};
    struct {
        GLint from_depth, source_level, source_size, out_size;
    } hiz_loc{};
    struct {
        GLint object_to_clip, eye;
    } occluder_loc{};

    ~Impl() {
        for (GLuint p : {draw_program, mark_program, frustum_program, occlusion_program, hiz_program, occluder_program})
            glDeleteProgram(p);
        const GLuint buffers[] = {control_points, cull_flags,        max_displacement, texcoords,   plane_values,
                                  backpatch_flags, counters,         occluder_vertices, tangents,   drawn_marks,
                                  front_marks,     tess_scale};
        glDeleteBuffers(12, buffers);
        const GLuint textures[] = {displacement_texture, color, ids, depth, hiz, vis_color, vis_depth};
        glDeleteTextures(7, textures);
        glDeleteFramebuffers(1, &fbo);
        glDeleteFramebuffers(1, &vis_fbo);
        glDeleteVertexArrays(1, &vao);
        if (timer_queries[0]) glDeleteQueries(5, timer_queries);
    }

    void link_cull_programs() {
        glDeleteProgram(frustum_program);
        glDeleteProgram(occlusion_program);
        const std::string defines = fma_via_double ? "#define PATCHCULL_FMA_VIA_DOUBLE 1\n" : "";
        frustum_program = link_program({{"cull_frustum.comp.glsl", GL_COMPUTE_SHADER}}, "cull_frustum", defines);
        const GLuint fp = frustum_program;
        frustum_loc = {glGetUniformLocation(fp, "u_plane_rows"), glGetUniformLocation(fp, "u_plane_normal_length"),
                       glGetUniformLocation(fp, "u_patch_count"), glGetUniformLocation(fp, "u_has_displacement"),
                       glGetUniformLocation(fp, "u_write_plane_values")};
        occlusion_program =
            link_program({{"cull_occlusion.comp.glsl", GL_COMPUTE_SHADER}}, "cull_occlusion", defines);
        const GLuint op = occlusion_program;
        occlusion_loc = {glGetUniformLocation(op, "u_plane_rows"),     glGetUniformLocation(op, "u_plane_normal_length"),
                         glGetUniformLocation(op, "u_patch_count"),    glGetUniformLocation(op, "u_has_displacement"),
                         glGetUniformLocation(op, "u_has_backpatch"),  glGetUniformLocation(op, "u_tests"),
                         glGetUniformLocation(op, "u_object_to_clip"), glGetUniformLocation(op, "u_screen"),
                         glGetUniformLocation(op, "u_hiz_levels")};
    }

    void resize(int w, int h) {
        if (w == width && h == height) return;
        if (w < 1 || h < 1 || w > 8192 || h > 8192)
            throw Error("GL: framebuffer size " + std::to_string(w) + "x" + std::to_string(h) + " outside [1, 8192]");
        const GLuint textures[] = {color, ids, depth};
        glDeleteTextures(3, textures);
        glCreateTextures(GL_TEXTURE_2D, 1, &color);
        glCreateTextures(GL_TEXTURE_2D, 1, &ids);
        glCreateTextures(GL_TEXTURE_2D, 1, &depth);
        glTextureStorage2D(color, 1, GL_RGBA8, w, h);
        glTextureStorage2D(ids, 1, GL_R32UI, w, h);
        glTextureStorage2D(depth, 1, GL_DEPTH_COMPONENT32F, w, h);
        for (GLuint t : {color, ids, depth}) {
            glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        }
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color, 0);
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT1, ids, 0);
        glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth, 0);
        const GLenum draw_buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
        glNamedFramebufferDrawBuffers(fbo, 2, draw_buffers);
        const GLenum status = glCheckNamedFramebufferStatus(fbo, GL_DRAW_FRAMEBUFFER);
        if (status != GL_FRAMEBUFFER_COMPLETE) throw Error("GL: framebuffer incomplete (" + hex(status) + ")");
        width = w;
        height = h;
        check_gl("framebuffer resize");
    }

    void bind_buffers() const {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingControlPoints, control_points);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingCullFlags, cull_flags);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingMaxDisplacement, max_displacement);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingPatchTexcoords, texcoords);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingPlaneValues, plane_values);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingBackPatchFlags, backpatch_flags);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingCullCounters, counters);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingOccluderVertices, occluder_vertices);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingPatchTangents, tangents);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingPatchTessScale, tess_scale);
    }

    void set_patches(const float* aos_points, std::size_t n, const PatchAttributes& a, bool keep_flags = false) {
        if (!a.max_displacement.empty() && a.max_displacement.size() != n)
            throw Error("GL: set_patches: max_displacement has " + std::to_string(a.max_displacement.size()) +
                        " entries for " + std::to_string(n) + " patches");
        if (!a.texcoords.empty() && a.texcoords.size() != n)
            throw Error("GL: set_patches: texcoords has " + std::to_string(a.texcoords.size()) + " entries for " +
                        std::to_string(n) + " patches");
        if (!a.tangent_index.empty() && a.tangent_index.size() != n)
            throw Error("GL: set_patches: tangent_index has " + std::to_string(a.tangent_index.size()) +
                        " entries for " + std::to_string(n) + " patches");
        if (!a.depth.empty() && a.depth.size() != n)
            throw Error("GL: set_patches: depth has " + std::to_string(a.depth.size()) + " entries for " +
                        std::to_string(n) + " patches");
        for (std::int32_t t : a.tangent_index)
            if (t >= 0 && static_cast<std::size_t>(t) >= a.tangents.size())
                throw Error("GL: set_patches: tangent_index " + std::to_string(t) + " is past the " +
                            std::to_string(a.tangents.size()) + " tangent patches");
        if (n > 0x7FFFFFFFu / kPatchPoints) throw Error("GL: set_patches: too many patches for one draw (" + std::to_string(n) + ")");
        if (keep_flags && n != count)
            throw Error("GL: update_patches: " + std::to_string(n) + " patches for a set of " + std::to_string(count));
        count = n;
        upload(control_points, n * kPatchPoints * 4 * sizeof(float), aos_points);
        if (!keep_flags) {
            upload(cull_flags, n * sizeof(std::uint32_t), nullptr);
            glClearNamedBufferData(cull_flags, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
        }
        has_max_displacement = !a.max_displacement.empty();
        upload(max_displacement, has_max_displacement ? n * sizeof(float) : 0, a.max_displacement.data());
        std::vector<Vec2> uv(4 * n);
        for (std::size_t p = 0; p < n; ++p)
            for (int c = 0; c < 4; ++c)
                uv[4 * p + c] = a.texcoords.empty() ? Vec2{float(c & 1), float(c >> 1)} : a.texcoords[p][c];
        upload(texcoords, uv.size() * sizeof(Vec2), uv.data());
        // Tangent patches: kTangentVec4s vec4 per patch (at least one vec4 so the buffer exists);
        // element 0's w flags the patch as having them.
        std::vector<Vec4> tangent_data(std::max<std::size_t>(1, a.tangent_index.empty() ? 1 : n * sh::kTangentVec4s));
        for (std::size_t p = 0; p < a.tangent_index.size(); ++p) {
            if (a.tangent_index[p] < 0) continue;
            const TangentPatches& t = a.tangents[static_cast<std::size_t>(a.tangent_index[p])];
            Vec4* out = &tangent_data[p * sh::kTangentVec4s];
            for (int k = 0; k < 12; ++k) out[k] = {t.du[k].x, t.du[k].y, t.du[k].z, 0.0f};
            for (int k = 0; k < 12; ++k) out[12 + k] = {t.dv[k].x, t.dv[k].y, t.dv[k].z, 0.0f};
            out[0].w = 1.0f;
        }
        upload(tangents, tangent_data.size() * sizeof(Vec4), tangent_data.data());
        has_tangents = !a.tangent_index.empty();
        upload(plane_values, 0, nullptr);
        const int deepest = a.depth.empty() ? 0 : *std::max_element(a.depth.begin(), a.depth.end());
        std::vector<float> scales(std::max<std::size_t>(n, 1), 1.0f);
        for (std::size_t p = 0; p < a.depth.size(); ++p)
            scales[p] = std::ldexp(1.0f, std::min(deepest - int(a.depth[p]), 6));  // 2^6 = 64: any level saturates
        max_tess_scale = *std::max_element(scales.begin(), scales.end());
        upload(tess_scale, scales.size() * sizeof(float), scales.data());
        upload(drawn_marks, n * sizeof(std::uint32_t), nullptr);
        upload(front_marks, n * sizeof(std::uint32_t), nullptr);
        if (!keep_flags) {
            upload(backpatch_flags, n * sizeof(std::uint32_t), nullptr);
            primed = false;
        }
        check_gl("set_patches");
    }

    // Hi-Z, statuses and the combined cull pass (occlusion_pipeline.cpp).
    void ensure_hiz();
    void build_hiz();
    void prime_statuses();
    // displaced: the drawn surface is displaced (a map is set and drawing displaces); then, without
    // per-patch margins, the Hi-Z test is skipped (the margins tell which patches are flat).
    void cull_occlusion(const Mat4& object_to_clip, std::uint32_t tests, const std::uint8_t* backpatch,
                        GLuint backpatch_buffer, bool displaced);

    // Sets the patch programs' uniforms for params (draw_program with color_mode; mark_program the
    // same geometry); returns the effective tessellation level. mark_drawn: the draw records the
    // patches it tessellates in drawn_marks (render, render_frame; not the status image).
    int set_draw_uniforms(const RenderParams& params, const Mat4& object_to_clip, GLuint color_mode,
                          bool mark_drawn = false) {
        const int level = std::clamp(params.tess_level, 1, 64);
        Mat4 view_inverse;
        Vec3 eye{0, 0, 0};
        if (invert(params.view, view_inverse)) eye = {view_inverse.at(0, 3), view_inverse.at(1, 3), view_inverse.at(2, 3)};
        const bool displace = params.displace && has_displacement_map;
        // The front-facing test evaluates the undisplaced patch: a displaced surface is drawn
        // two-sided (no back-patch test bounds it; backpatch.h).
        const bool one_sided = params.discard_back_facing && !displace;
        for (const auto& [dp, loc] : {std::pair{draw_program, &draw_loc}, std::pair{mark_program, &mark_loc}}) {
            glProgramUniform1f(dp, loc->tess_level, static_cast<float>(level));
            glProgramUniform1i(dp, loc->adaptive, params.adaptive_tess ? 1 : 0);
            glProgramUniform1f(dp, loc->tess_reference,
                               params.tess_reference_distance > 0 ? params.tess_reference_distance : 1.0f);
            glProgramUniformMatrix4fv(dp, loc->object_to_clip, 1, GL_FALSE, object_to_clip.m);
            glProgramUniform1i(dp, loc->displace, displace ? 1 : 0);
            glProgramUniform1f(dp, loc->displacement_scale, displacement_scale);
            glProgramUniform1f(dp, loc->displacement_midlevel, displacement_midlevel);
            glProgramUniform3f(dp, loc->eye, eye.x, eye.y, eye.z);
            glProgramUniform1ui(dp, loc->color_mode, color_mode);
            glProgramUniform1i(dp, loc->has_tangents, has_tangents ? 1 : 0);
            glProgramUniform1i(dp, loc->discard_back_facing, one_sided ? 1 : 0);
            glProgramUniform1i(dp, loc->mark_drawn, dp == draw_program && mark_drawn ? 1 : 0);
        }
        if (mark_drawn && count > 0) glClearNamedBufferData(drawn_marks, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
        glProgramUniformMatrix4fv(occluder_program, occluder_loc.object_to_clip, 1, GL_FALSE, object_to_clip.m);
        glProgramUniform3f(occluder_program, occluder_loc.eye, eye.x, eye.y, eye.z);
        return level;
    }

    // Binds target (fbo, or vis_fbo) with the fixed-function state of every draw and clears it.
    void begin_target(GLuint target, int w, int h) {
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target);
        glViewport(0, 0, w, h);
        glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glDisable(GL_CULL_FACE);
        glDisable(GL_BLEND);
        const float background[4] = {0.12f, 0.12f, 0.14f, 1.0f};
        const GLuint no_id[4] = {sh::kIdBackground, 0, 0, 0};
        const float far_depth = 1.0f;
        glClearNamedFramebufferfv(target, GL_COLOR, 0, background);
        if (target == fbo) glClearNamedFramebufferuiv(target, GL_COLOR, 1, no_id);
        glClearNamedFramebufferfv(target, GL_DEPTH, 0, &far_depth);
    }

    void draw_occluders() {
        if (occluder_triangles == 0) return;
        glUseProgram(occluder_program);
        glBindVertexArray(vao);
        bind_buffers();
        glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(3 * occluder_triangles));
        glBindVertexArray(0);
        glUseProgram(0);
    }

    // Draws the patches whose flag word w has (w & mask) == value (into the bound framebuffer)
    // with the draw program, or with the mark program (mark_front: marks into front_marks).
    void draw_patches(int level, GLuint mask, GLuint value, bool mark_front = false) {
        if (count == 0) return;
        const GLuint dp = mark_front ? mark_program : draw_program;
        const DrawUniforms& loc = mark_front ? mark_loc : draw_loc;
        glProgramUniform1ui(dp, loc.draw_mask, mask);
        glProgramUniform1ui(dp, loc.draw_value, value);
        glUseProgram(dp);
        glBindVertexArray(vao);
        bind_buffers();
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingPatchMarks, mark_front ? front_marks : drawn_marks);
        glBindTextureUnit(sh::kTextureUnitDisplacement, displacement_texture);
        glPatchParameteri(GL_PATCH_VERTICES, kPatchPoints);
        // llvmpipe workaround 2 (header): at most 65536 / (L+1)^2 patches per sub-draw, L the
        // largest level of the set (depth scales included).
        const int top = std::min(64, static_cast<int>(static_cast<float>(level) * max_tess_scale));
        const std::size_t per_draw = std::max<std::size_t>(1, 65536 / static_cast<std::size_t>((top + 1) * (top + 1)));
        std::vector<GLint> firsts;
        std::vector<GLsizei> counts;
        for (std::size_t first = 0; first < count; first += per_draw) {
            firsts.push_back(static_cast<GLint>(first * kPatchPoints));
            counts.push_back(static_cast<GLsizei>(std::min(per_draw, count - first) * kPatchPoints));
        }
        glMultiDrawArrays(GL_PATCHES, firsts.data(), counts.data(), static_cast<GLsizei>(firsts.size()));
        glBindVertexArray(0);
        glUseProgram(0);
    }
};

}  // namespace patchcull::gl
