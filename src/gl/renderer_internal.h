// Internals of PatchRenderer (patchcull/gl/gl_renderer.h) shared by the renderer's sources:
// patch_renderer.cpp (buffers, programs, drawing, read-backs) and status_image.cpp (the status
// image and frame comparison). Not a public header.
#pragma once

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "gl_util.h"
#include "patchcull/core/error.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/patch_runs.h"
#include "patchcull/gl/gl_renderer.h"
#include "png_file.h"
#include "shader_sources.h"
#include "shared.h"

namespace patchcull::gl {

namespace sh = shared;

using namespace detail;

struct PatchRenderer::Impl {
    GLuint vao = 0;
    GLuint mark_program = 0;          // the patch program with PATCHCULL_MARK_FRONT (patch.frag.glsl)
    GLuint list_program = 0;          // the patch program with PATCHCULL_DRAW_LIST (patch.vert.glsl): draw_indirect
    bool indirect_count = false;      // glMultiDrawArraysIndirectCount is there (GL 4.6 or the extension)
    bool indirect_count_arb = false;  // ... as GL_ARB_indirect_parameters' function
    GLuint draw_program = 0, occluder_program = 0;
    GLuint control_points = 0, cull_flags = 0, max_displacement = 0, texcoords = 0, ranges = 0;
    GLuint occluder_vertices = 0, tangents = 0;
    GLuint drawn_marks = 0, front_marks = 0;  // uint per patch at kBindingPatchMarks (shared.h)
    GLuint tess_scale = 0;                    // float per patch at kBindingPatchTessScale
    float max_tess_scale = 1;                 // largest entry of tess_scale (the draw split)
    GLuint displacement_texture = 0;
    float displacement_scale = 0, displacement_midlevel = 0.5f;
    bool has_displacement_map = false;
    bool has_max_displacement = false;
    bool has_ranges = false;
    DisplacementRuns runs;                          // PatchRenderer::undisplaced_runs / displaced_runs (set_patches)
    bool has_tangents = false;                      // the tangent buffer holds kTangentVec4s vec4 per patch
    int frame_level = 1;                            // begin_frame's effective tessellation level
    ClipDepth clip_depth = ClipDepth::zero_to_one;  // the last set_draw_uniforms' RenderParams::depth
    std::uint64_t flag_generation = 0;              // PatchRenderer::flag_generation
    GLuint fbo = 0, color = 0, ids = 0, depth = 0;
    int width = 0, height = 0;
    std::size_t count = 0;
    std::size_t occluder_triangles = 0;
    std::vector<std::uint8_t> occluder_one_sided;  // per triangle: drawn with back faces culled
    std::vector<std::uint8_t> occluder_culled;     // per triangle: culled by the object level
    // Status visualisation: its own colour + depth framebuffer.
    GLuint vis_fbo = 0, vis_color = 0, vis_depth = 0;
    int vis_width = 0, vis_height = 0;

    // Uniform locations of a patch program (draw_program, mark_program).
    struct DrawUniforms {
        GLint tess_level, draw_mask, draw_value, adaptive, tess_reference, object_to_clip, displace, displacement_scale,
            displacement_midlevel, eye, color_mode, has_tangents, mark_drawn, discard_back_facing, has_margins;
        void locate(GLuint p) {
            *this = {glGetUniformLocation(p, "u_tess_level"),
                     glGetUniformLocation(p, "u_draw_mask"),
                     glGetUniformLocation(p, "u_draw_value"),
                     glGetUniformLocation(p, "u_adaptive"),
                     glGetUniformLocation(p, "u_tess_reference"),
                     glGetUniformLocation(p, "u_object_to_clip"),
                     glGetUniformLocation(p, "u_displace"),
                     glGetUniformLocation(p, "u_displacement_scale"),
                     glGetUniformLocation(p, "u_displacement_midlevel"),
                     glGetUniformLocation(p, "u_eye"),
                     glGetUniformLocation(p, "u_color_mode"),
                     glGetUniformLocation(p, "u_has_tangents"),
                     glGetUniformLocation(p, "u_mark_drawn"),
                     glGetUniformLocation(p, "u_discard_back_facing"),
                     glGetUniformLocation(p, "u_has_margins")};
        }
    };
    DrawUniforms draw_loc{}, mark_loc{}, list_loc{};
    struct {
        GLint object_to_clip, eye;
    } occluder_loc{};

    ~Impl() {
        for (GLuint p : {draw_program, mark_program, list_program, occluder_program}) glDeleteProgram(p);
        const GLuint buffers[] = {control_points,    cull_flags, max_displacement, texcoords,   ranges,
                                  occluder_vertices, tangents,   drawn_marks,      front_marks, tess_scale};
        glDeleteBuffers(10, buffers);
        const GLuint textures[] = {displacement_texture, color, ids, depth, vis_color, vis_depth};
        glDeleteTextures(6, textures);
        glDeleteFramebuffers(1, &fbo);
        glDeleteFramebuffers(1, &vis_fbo);
        glDeleteVertexArrays(1, &vao);
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
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingOccluderVertices, occluder_vertices);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingPatchTangents, tangents);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingPatchTessScale, tess_scale);
    }

    void set_patches(const float* aos_points, std::size_t n, const PatchAttributes& a, bool keep_flags = false) {
        for (std::size_t p = 0; p < n; ++p) {  // weights <= 0 refused (patch.h)
            const float* q = aos_points + p * kPatchPoints * 4;
            BezierPatch patch;
            for (int k = 0; k < kPatchPoints; ++k) patch.cp[k] = {q[4 * k], q[4 * k + 1], q[4 * k + 2], q[4 * k + 3]};
            check_patch_weights(patch, p);
        }
        if (!a.max_displacement.empty() && a.max_displacement.size() != n)
            throw Error("GL: set_patches: max_displacement has " + std::to_string(a.max_displacement.size()) +
                        " entries for " + std::to_string(n) + " patches");
        if (!a.texcoords.empty() && a.texcoords.size() != n)
            throw Error("GL: set_patches: texcoords has " + std::to_string(a.texcoords.size()) + " entries for " +
                        std::to_string(n) + " patches");
        if (!a.tangent_index.empty() && a.tangent_index.size() != n)
            throw Error("GL: set_patches: tangent_index has " + std::to_string(a.tangent_index.size()) +
                        " entries for " + std::to_string(n) + " patches");
        if (!a.displacement_ranges.empty() && a.displacement_ranges.size() != n)
            throw Error("GL: set_patches: displacement_ranges has " + std::to_string(a.displacement_ranges.size()) +
                        " entries for " + std::to_string(n) + " patches");
        if (!a.depth.empty() && a.depth.size() != n)
            throw Error("GL: set_patches: depth has " + std::to_string(a.depth.size()) + " entries for " +
                        std::to_string(n) + " patches");
        for (std::int32_t t : a.tangent_index)
            if (t >= 0 && static_cast<std::size_t>(t) >= a.tangents.size())
                throw Error("GL: set_patches: tangent_index " + std::to_string(t) + " is past the " +
                            std::to_string(a.tangents.size()) + " tangent patches");
        if (n > 0x7FFFFFFFu / kPatchPoints)
            throw Error("GL: set_patches: too many patches for one draw (" + std::to_string(n) + ")");
        if (keep_flags && n != count)
            throw Error("GL: update_patches: " + std::to_string(n) + " patches for a set of " + std::to_string(count));
        count = n;
        upload(control_points, n * kPatchPoints * 4 * sizeof(float), aos_points);
        if (!keep_flags) {
            upload(cull_flags, n * sizeof(std::uint32_t), nullptr);
            glClearNamedBufferData(cull_flags, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
            ++flag_generation;
        }
        // Margins: given, or the ranges' max |D|.
        std::vector<float> margins = a.max_displacement;
        if (margins.empty() && !a.displacement_ranges.empty())
            for (const DisplacementRange& r : a.displacement_ranges) margins.push_back(r.max_abs());
        has_max_displacement = !margins.empty();
        upload(max_displacement, has_max_displacement ? n * sizeof(float) : 0, margins.data());
        has_ranges = !a.displacement_ranges.empty();
        upload(ranges, has_ranges ? n * sizeof(DisplacementRange) : 0, a.displacement_ranges.data());
        runs = displacement_runs(n, margins, a.displacement_ranges);
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
        const int deepest = a.depth.empty() ? 0 : *std::max_element(a.depth.begin(), a.depth.end());
        std::vector<float> scales(std::max<std::size_t>(n, 1), 1.0f);
        for (std::size_t p = 0; p < a.depth.size(); ++p)
            scales[p] = std::ldexp(1.0f, std::min(deepest - int(a.depth[p]), 6));  // 2^6 = 64: any level saturates
        max_tess_scale = *std::max_element(scales.begin(), scales.end());
        upload(tess_scale, scales.size() * sizeof(float), scales.data());
        upload(drawn_marks, n * sizeof(std::uint32_t), nullptr);
        upload(front_marks, n * sizeof(std::uint32_t), nullptr);
        check_gl("set_patches");
    }

    // Sets the patch programs' uniforms for params (draw_program with color_mode; mark_program the
    // same geometry); returns the effective tessellation level. mark_drawn: the draw records the
    // patches it tessellates in drawn_marks (render, render_frame; not the status image).
    // The depth test of the convention: GL_LESS, or GL_GREATER (reversed); or_equal: GL_LEQUAL /
    // GL_GEQUAL.
    GLenum depth_less(bool or_equal = false) const {
        if (is_reversed(clip_depth)) return or_equal ? GL_GEQUAL : GL_GREATER;
        return or_equal ? GL_LEQUAL : GL_LESS;
    }

    int set_draw_uniforms(const RenderParams& params, const Mat4& object_to_clip, GLuint color_mode,
                          bool mark_drawn = false) {
        clip_depth = params.depth;
        const int level = std::clamp(params.tess_level, 1, 64);
        Mat4 view_inverse;
        Vec3 eye{0, 0, 0};
        if (invert(params.view, view_inverse))
            eye = {view_inverse.at(0, 3), view_inverse.at(1, 3), view_inverse.at(2, 3)};
        const bool displace = params.displace && has_displacement_map;
        // The front-facing test evaluates the undisplaced patch: displaced patches are drawn
        // two-sided (no back-patch test bounds them; backpatch.h); patch_displaced.h says which.
        const bool one_sided = params.discard_back_facing;
        for (const auto& [dp, loc] : {std::pair{draw_program, &draw_loc}, std::pair{mark_program, &mark_loc},
                                      std::pair{list_program, &list_loc}}) {
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
            glProgramUniform1i(dp, loc->has_margins, has_max_displacement ? 1 : 0);
            glProgramUniform1i(dp, loc->mark_drawn, dp != mark_program && mark_drawn ? 1 : 0);
        }
        if (mark_drawn && count > 0)
            glClearNamedBufferData(drawn_marks, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
        glProgramUniformMatrix4fv(occluder_program, occluder_loc.object_to_clip, 1, GL_FALSE, object_to_clip.m);
        glProgramUniform3f(occluder_program, occluder_loc.eye, eye.x, eye.y, eye.z);
        return level;
    }

    // Binds target (fbo, or vis_fbo) with the fixed-function state of every draw: clip depth of
    // the convention, its depth test (depth_less) with writes, no face culling, no blending.
    void bind_target(GLuint target, int w, int h) {
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target);
        glViewport(0, 0, w, h);
        glClipControl(GL_LOWER_LEFT,
                      clip_depth == ClipDepth::minus_one_to_one ? GL_NEGATIVE_ONE_TO_ONE : GL_ZERO_TO_ONE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(depth_less());
        glDepthMask(GL_TRUE);
        glDisable(GL_CULL_FACE);
        glDisable(GL_BLEND);
    }

    // bind_target, then clears it (colour dark grey, id 0, depth 1, or 0 when reversed).
    void begin_target(GLuint target, int w, int h) {
        bind_target(target, w, h);
        const float background[4] = {0.12f, 0.12f, 0.14f, 1.0f};
        const GLuint no_id[4] = {sh::kIdBackground, 0, 0, 0};
        const float far_depth = is_reversed(clip_depth) ? 0.0f : 1.0f;
        glClearNamedFramebufferfv(target, GL_COLOR, 0, background);
        if (target == fbo) glClearNamedFramebufferuiv(target, GL_COLOR, 1, no_id);
        glClearNamedFramebufferfv(target, GL_DEPTH, 0, &far_depth);
    }

    // Draws the occluders: the two-sided triangles, then the one-sided ones with back faces
    // culled (counter-clockwise front); honour_culls skips the triangles of set_culled_occluders.
    void draw_occluders(bool honour_culls) {
        if (occluder_triangles == 0) return;
        std::vector<GLint> firsts[2];
        std::vector<GLsizei> counts[2];
        for (std::size_t t = 0; t < occluder_triangles;) {
            const bool skip = honour_culls && occluder_culled[t];
            const std::uint8_t side = occluder_one_sided[t];
            std::size_t end = t + 1;
            while (end < occluder_triangles && (honour_culls && occluder_culled[end]) == skip &&
                   occluder_one_sided[end] == side)
                ++end;
            if (!skip) {
                firsts[side].push_back(static_cast<GLint>(3 * t));
                counts[side].push_back(static_cast<GLsizei>(3 * (end - t)));
            }
            t = end;
        }
        glUseProgram(occluder_program);
        glBindVertexArray(vao);
        bind_buffers();
        for (int side = 0; side < 2; ++side) {
            if (firsts[side].empty()) continue;
            if (side == 1) {
                glEnable(GL_CULL_FACE);
                glCullFace(GL_BACK);
                glFrontFace(GL_CCW);
            }
            glMultiDrawArrays(GL_TRIANGLES, firsts[side].data(), counts[side].data(),
                              static_cast<GLsizei>(firsts[side].size()));
        }
        glDisable(GL_CULL_FACE);
        glBindVertexArray(0);
        glUseProgram(0);
    }

    // llvmpipe workaround 2 (header): at most 65536 / (L+1)^2 patches per sub-draw, L the largest
    // level of the set at `level` (depth scales included).
    std::size_t patches_per_draw(int level) const {
        return max_patches_per_draw(std::min(64, static_cast<int>(static_cast<float>(level) * max_tess_scale)));
    }

    // Binds program dp (its selection mask and value set) with the buffers, marks, texture and
    // patch size of every patch draw.
    void begin_patch_draw(GLuint dp, const DrawUniforms& loc, GLuint mask, GLuint value, bool mark_front) {
        glProgramUniform1ui(dp, loc.draw_mask, mask);
        glProgramUniform1ui(dp, loc.draw_value, value);
        glUseProgram(dp);
        glBindVertexArray(vao);
        bind_buffers();
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingPatchMarks, mark_front ? front_marks : drawn_marks);
        glBindTextureUnit(sh::kTextureUnitDisplacement, displacement_texture);
        glPatchParameteri(GL_PATCH_VERTICES, kPatchPoints);
    }

    // Draws the patches whose flag word w has (w & mask) == value (into the bound framebuffer)
    // with the draw program, or with the mark program (mark_front: marks into front_marks).
    // spans: only those patches (PatchSpan, validated by the caller); null: every patch.
    void draw_patches(int level, GLuint mask, GLuint value, bool mark_front = false,
                      const std::vector<PatchSpan>* spans = nullptr) {
        if (count == 0) return;
        begin_patch_draw(mark_front ? mark_program : draw_program, mark_front ? mark_loc : draw_loc, mask, value,
                         mark_front);
        const std::size_t per_draw = patches_per_draw(level);
        std::vector<GLint> firsts;
        std::vector<GLsizei> counts;
        const std::vector<PatchSpan> all{{0, count}};
        for (const PatchSpan& span : spans ? *spans : all) {
            const std::size_t end = span.first + span.count;
            for (std::size_t first = span.first; first < end; first += per_draw) {
                firsts.push_back(static_cast<GLint>(first * kPatchPoints));
                counts.push_back(static_cast<GLsizei>(std::min(per_draw, end - first) * kPatchPoints));
            }
        }
        if (!firsts.empty())
            glMultiDrawArrays(GL_PATCHES, firsts.data(), counts.data(), static_cast<GLsizei>(firsts.size()));
        glBindVertexArray(0);
        glUseProgram(0);
    }

    // The compacted draw (PatchRenderer::draw_indirect, validated by the caller): the list
    // program (every listed patch drawn: selection 0, 0) over d's commands.
    void draw_list(const IndirectDraw& d) {
        if (count == 0 || d.command_count == 0) return;
        begin_patch_draw(list_program, list_loc, 0u, 0u, false);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingDrawList, d.list);
        glBindBuffer(GL_DRAW_INDIRECT_BUFFER, d.commands);
        // GL takes the byte offset into the bound indirect buffer as a pointer.
        // NOLINTNEXTLINE(performance-no-int-to-ptr)
        const auto* offset = reinterpret_cast<const void*>(static_cast<std::uintptr_t>(d.first_command * 16));
        const auto max_draws = static_cast<GLsizei>(d.command_count);
        if (d.draw_count && indirect_count) {
            glBindBuffer(GL_PARAMETER_BUFFER_ARB, d.draw_count);
            if (indirect_count_arb)
                glMultiDrawArraysIndirectCountARB(GL_PATCHES, offset, static_cast<GLintptr>(d.draw_count_offset),
                                                  max_draws, 0);
            else
                glMultiDrawArraysIndirectCount(GL_PATCHES, offset, static_cast<GLintptr>(d.draw_count_offset),
                                               max_draws, 0);
            glBindBuffer(GL_PARAMETER_BUFFER_ARB, 0);
        } else {
            glMultiDrawArraysIndirect(GL_PATCHES, offset, max_draws, 0);
        }
        glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
        glBindVertexArray(0);
        glUseProgram(0);
    }
};

}  // namespace patchcull::gl
