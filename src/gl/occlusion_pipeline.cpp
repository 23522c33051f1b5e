// The occlusion pipeline of PatchRenderer (patchcull/gl_renderer.h, seed 000 §3-§4.1): the Hi-Z
// pyramid built in compute (shaders/hiz_build.comp.glsl), the combined frustum + back-patch hook +
// Hi-Z cull pass (shaders/cull_occlusion.comp.glsl), the per-patch temporal status, the two-pass
// render_frame with per-pass timing, and the status visualisation.
#include <epoxy/gl.h>
#include <stb_image_write.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <iterator>
#include <cstring>
#include <string>
#include <vector>

#include "patchcull/error.h"
#include "patchcull/gl_renderer.h"
#include "patchcull/hiz.h"
#include "renderer_internal.h"

namespace patchcull::gl {

// ---- Impl: Hi-Z, statuses, cull pass ---------------------------------------------------------

// (Re)creates the pyramid texture for the framebuffer size: hiz.h's level sizes
// W_l = ceil(W / 2^(l+1)) in a power-of-two texture of HiZPyramid::level_count levels whose
// level l is (bit_ceil(W_0) >> l) x (bit_ceil(H_0) >> l) (at least 1), which holds W_l x H_l
// (seed 000 §4.1's NPOT enlargement; the unused texels are never read).
void PatchRenderer::Impl::ensure_hiz() {
    if (hiz && hiz_width == width && hiz_height == height) return;
    glDeleteTextures(1, &hiz);
    const int levels = HiZPyramid::level_count(width, height);
    hiz_layout.assign(static_cast<std::size_t>(levels), HiZLevel{});
    std::size_t offset = 0;
    int w = width, h = height;
    for (int l = 0; l < levels; ++l) {
        w = (w + 1) / 2;
        h = (h + 1) / 2;
        hiz_layout[static_cast<std::size_t>(l)] = {w, h, offset};
        offset += static_cast<std::size_t>(w) * h;
    }
    const int pot_w = static_cast<int>(std::bit_ceil(static_cast<unsigned>(hiz_layout[0].width)));
    const int pot_h = static_cast<int>(std::bit_ceil(static_cast<unsigned>(hiz_layout[0].height)));
    glCreateTextures(GL_TEXTURE_2D, 1, &hiz);
    glTextureStorage2D(hiz, levels, GL_R32F, pot_w, pot_h);
    glTextureParameteri(hiz, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    glTextureParameteri(hiz, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    // Zero everywhere (seed: unused texels 0), so that nothing undefined is ever stored.
    const float zero = 0.0f;
    for (int l = 0; l < levels; ++l) glClearTexImage(hiz, l, GL_RED, GL_FLOAT, &zero);
    hiz_width = width;
    hiz_height = height;
    check_gl("Hi-Z texture");
}

void PatchRenderer::Impl::build_hiz() {
    ensure_hiz();
    const GLuint hp = hiz_program;
    glUseProgram(hp);
    glBindTextureUnit(sh::kTextureUnitDepth, depth);
    glBindTextureUnit(sh::kTextureUnitHiZ, hiz);
    int source_w = width, source_h = height;
    for (std::size_t l = 0; l < hiz_layout.size(); ++l) {
        const HiZLevel& lv = hiz_layout[l];
        glProgramUniform1i(hp, hiz_loc.from_depth, l == 0 ? 1 : 0);
        glProgramUniform1i(hp, hiz_loc.source_level, l == 0 ? 0 : static_cast<GLint>(l - 1));
        glProgramUniform2i(hp, hiz_loc.source_size, source_w, source_h);
        glProgramUniform2i(hp, hiz_loc.out_size, lv.width, lv.height);
        glBindImageTexture(sh::kImageUnitHiZOut, hiz, static_cast<GLint>(l), GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
        glDispatchCompute((static_cast<GLuint>(lv.width) + sh::kHiZGroupSize - 1) / sh::kHiZGroupSize,
                          (static_cast<GLuint>(lv.height) + sh::kHiZGroupSize - 1) / sh::kHiZGroupSize, 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                        GL_TEXTURE_UPDATE_BARRIER_BIT);
        source_w = lv.width;
        source_h = lv.height;
    }
    glBindImageTexture(sh::kImageUnitHiZOut, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glUseProgram(0);
    check_gl("build_hiz");
}

// Tags the even-indexed patches visible, the others not (seed 000 §3's first frame).
void PatchRenderer::Impl::prime_statuses() {
    std::vector<std::uint32_t> words(count);
    for (std::size_t p = 0; p < count; p += 2) words[p] = sh::kStatusVisible;
    if (!words.empty())
        glNamedBufferSubData(cull_flags, 0, static_cast<GLsizeiptr>(words.size() * sizeof(std::uint32_t)),
                             words.data());
    primed = true;
}

void PatchRenderer::Impl::cull_occlusion(const Mat4& object_to_clip, std::uint32_t tests, const std::uint8_t* backpatch,
                                         GLuint backpatch_buffer, bool displaced) {
    if (displaced && !has_max_displacement) tests &= ~sh::kCullOcclusion;
    glClearNamedBufferData(counters, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    if (count == 0) return;
    const std::size_t groups = (count + sh::kCullGroupSize - 1) / sh::kCullGroupSize;
    if (groups > 65535) throw Error("GL: cull_occlusion: more than 65535 * 64 patches");
    if (tests & sh::kCullOcclusion) {
        if (!hiz || hiz_width != width || hiz_height != height)
            throw Error("GL: cull_occlusion: no Hi-Z pyramid for the framebuffer size (call build_hiz)");
    }
    if (backpatch_buffer) {
        GLint64 size = 0;
        if (glIsBuffer(backpatch_buffer)) glGetNamedBufferParameteri64v(backpatch_buffer, GL_BUFFER_SIZE, &size);
        if (size < static_cast<GLint64>(count * sizeof(std::uint32_t)))
            throw Error("GL: cull_occlusion: back-patch buffer " + std::to_string(backpatch_buffer) +
                        " is not a buffer of patch_count() uints");
        // Written by another program's compute shader: make those writes visible here.
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    } else if (backpatch) {
        std::vector<std::uint32_t> flags(count);
        for (std::size_t p = 0; p < count; ++p) flags[p] = backpatch[p] ? 1u : 0u;
        glNamedBufferSubData(backpatch_flags, 0, static_cast<GLsizeiptr>(flags.size() * sizeof(std::uint32_t)),
                             flags.data());
    }
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, ClipDepth::zero_to_one);
    const GLuint op = occlusion_program;
    glProgramUniform4fv(op, occlusion_loc.rows, 6, &planes.rows[0].x);
    glProgramUniform1fv(op, occlusion_loc.normal_length, 6, planes.normal_length);
    glProgramUniform1ui(op, occlusion_loc.patch_count, static_cast<GLuint>(count));
    glProgramUniform1i(op, occlusion_loc.has_displacement, has_max_displacement ? 1 : 0);
    glProgramUniform1i(op, occlusion_loc.has_backpatch, backpatch || backpatch_buffer ? 1 : 0);
    glProgramUniform1ui(op, occlusion_loc.tests, tests);
    glProgramUniformMatrix4fv(op, occlusion_loc.object_to_clip, 1, GL_FALSE, object_to_clip.m);
    glProgramUniform2i(op, occlusion_loc.screen, width, height);
    glProgramUniform1i(op, occlusion_loc.hiz_levels, HiZPyramid::level_count(width, height));
    glUseProgram(op);
    bind_buffers();
    if (backpatch_buffer) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingBackPatchFlags, backpatch_buffer);
    glBindTextureUnit(sh::kTextureUnitHiZ, hiz);
    glDispatchCompute(static_cast<GLuint>(groups), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glUseProgram(0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingBackPatchFlags, backpatch_flags);
    primed = true;
    check_gl("cull_occlusion");
}

// ---- Hi-Z and the combined cull pass -----------------------------------------------------------

void PatchRenderer::build_hiz() { impl_->build_hiz(); }

int PatchRenderer::hiz_levels() const { return HiZPyramid::level_count(impl_->width, impl_->height); }

std::vector<float> PatchRenderer::read_hiz() const {
    const Impl& m = *impl_;
    if (!m.hiz || m.hiz_width != m.width || m.hiz_height != m.height)
        throw Error("GL: read_hiz: no Hi-Z pyramid for the framebuffer size (call build_hiz)");
    const HiZLevel& last = m.hiz_layout.back();
    std::vector<float> out(last.offset + static_cast<std::size_t>(last.width) * last.height);
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    for (std::size_t l = 0; l < m.hiz_layout.size(); ++l) {
        const HiZLevel& lv = m.hiz_layout[l];
        const std::size_t n = static_cast<std::size_t>(lv.width) * lv.height;
        glGetTextureSubImage(m.hiz, static_cast<GLint>(l), 0, 0, 0, lv.width, lv.height, 1, GL_RED, GL_FLOAT,
                             static_cast<GLsizei>(n * sizeof(float)), out.data() + lv.offset);
    }
    check_gl("read_hiz");
    return out;
}

void PatchRenderer::cull_occlusion(const Mat4& object_to_clip, CullMode mode, const std::uint8_t* backpatch_culled,
                                   std::uint32_t backpatch_buffer) {
    impl_->cull_occlusion(object_to_clip, static_cast<std::uint32_t>(mode), backpatch_culled, backpatch_buffer,
                          impl_->has_displacement_map);
}

void PatchRenderer::reset_visibility() { impl_->primed = false; }

// ---- the frame pipeline ------------------------------------------------------------------------

namespace {

// Marks pass boundaries: GL_TIMESTAMP queries, or steady_clock after glFinish().
class PassClock {
public:
    PassClock(TimingMethod method, GLuint* queries) : method_(method), queries_(queries) {
        if (method_ == TimingMethod::timer_query && !queries_[0]) glCreateQueries(GL_TIMESTAMP, 5, queries_);
    }
    void mark() {
        if (method_ == TimingMethod::wall_clock) {
            glFinish();
            wall_[marks_] = std::chrono::steady_clock::now();
        } else if (method_ == TimingMethod::timer_query) {
            glQueryCounter(queries_[marks_], GL_TIMESTAMP);
        }
        ++marks_;
    }
    // Milliseconds between mark i and mark i + 1 (waits for query results).
    std::vector<double> intervals() {
        std::vector<double> ms(static_cast<std::size_t>(std::max(marks_ - 1, 0)), 0.0);
        if (method_ == TimingMethod::wall_clock) {
            for (int i = 0; i + 1 < marks_; ++i)
                ms[static_cast<std::size_t>(i)] = std::chrono::duration<double, std::milli>(wall_[i + 1] - wall_[i]).count();
        } else if (method_ == TimingMethod::timer_query) {
            GLuint64 t[5] = {};
            for (int i = 0; i < marks_; ++i) glGetQueryObjectui64v(queries_[i], GL_QUERY_RESULT, &t[i]);
            for (int i = 0; i + 1 < marks_; ++i) ms[static_cast<std::size_t>(i)] = static_cast<double>(t[i + 1] - t[i]) * 1e-6;
        }
        return ms;
    }

private:
    TimingMethod method_;
    GLuint* queries_;
    std::chrono::steady_clock::time_point wall_[5];
    int marks_ = 0;
};

}  // namespace

FrameStats PatchRenderer::render_frame(const FrameParams& params) {
    Impl& m = *impl_;
    const RenderParams& rp = params.render;
    m.resize(rp.width, rp.height);
    const std::uint32_t tests = static_cast<std::uint32_t>(params.cull) & sh::kCullReasonMask;
    const bool two_pass = (tests & sh::kCullOcclusion) != 0;
    TimingMethod method = params.timing;
    if (method == TimingMethod::automatic) method = m.is_software ? TimingMethod::wall_clock : TimingMethod::timer_query;
    FrameStats stats;
    stats.patches = m.count;
    stats.two_pass = two_pass;
    stats.timing = method;

    if (!m.primed) m.prime_statuses();
    const Mat4 object_to_clip = rp.projection * rp.view;
    const bool displaced = m.has_displacement_map && rp.displace;
    const int level = m.set_draw_uniforms(rp, object_to_clip, sh::kColorPatch, true);
    PassClock clock(method, m.timer_queries);
    clock.mark();
    if (two_pass) {
        // 1. occluders + patches tagged visible.
        m.begin_target(m.fbo, m.width, m.height);
        m.draw_occluders();
        m.draw_patches(level, sh::kStatusVisible, sh::kStatusVisible);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        clock.mark();
        // 2. Hi-Z from that depth.
        m.build_hiz();
        clock.mark();
        // 3. test every patch, update statuses.
        m.cull_occlusion(object_to_clip, tests, params.backpatch_culled, params.backpatch_buffer, displaced);
        clock.mark();
        // 4. newly visible patches (seed 000 §3.1: skipped when aggressive).
        if (!params.aggressive) {
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, m.fbo);
            glViewport(0, 0, m.width, m.height);
            m.draw_patches(level, sh::kStatusVisible | sh::kStatusNewlyVisible,
                           sh::kStatusVisible | sh::kStatusNewlyVisible);
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        }
        clock.mark();
    } else {
        m.cull_occlusion(object_to_clip, tests, params.backpatch_culled, params.backpatch_buffer, displaced);
        clock.mark();
        m.begin_target(m.fbo, m.width, m.height);
        m.draw_occluders();
        m.draw_patches(level, sh::kStatusVisible, sh::kStatusVisible);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        clock.mark();
    }
    check_gl("render_frame");

    std::uint32_t c[sh::kCounterCount] = {};
    glGetNamedBufferSubData(m.counters, 0, sizeof c, c);
    check_gl("render_frame counters");
    stats.frustum_culled = c[sh::kCounterFrustum];
    stats.backpatch_culled = c[sh::kCounterBackPatch];
    stats.occlusion_culled = c[sh::kCounterOcclusion];
    stats.visible = c[sh::kCounterVisible];
    stats.newly_visible = c[sh::kCounterNewlyVisible];
    if (two_pass) {
        stats.pass1_drawn = c[sh::kCounterWasVisible];
        stats.pass2_drawn = params.aggressive ? 0 : stats.newly_visible;
    } else {
        stats.pass1_drawn = stats.visible;
    }
    const std::vector<double> ms = clock.intervals();
    if (!ms.empty()) {
        if (two_pass) {
            stats.pass1_ms = ms[0];
            stats.hiz_ms = ms[1];
            stats.cull_ms = ms[2];
            stats.pass2_ms = ms[3];
        } else {
            stats.cull_ms = ms[0];
            stats.pass1_ms = ms[1];
        }
        for (double t : ms) stats.total_ms += t;
    }
    return stats;
}

// ---- status visualisation ----------------------------------------------------------------------

std::vector<std::uint8_t> PatchRenderer::render_status_image(const RenderParams& view) {
    Impl& m = *impl_;
    if (view.width < 1 || view.height < 1 || view.width > 8192 || view.height > 8192)
        throw Error("GL: render_status_image: size outside [1, 8192]");
    if (view.width != m.vis_width || view.height != m.vis_height) {
        const GLuint textures[] = {m.vis_color, m.vis_depth};
        glDeleteTextures(2, textures);
        glCreateTextures(GL_TEXTURE_2D, 1, &m.vis_color);
        glCreateTextures(GL_TEXTURE_2D, 1, &m.vis_depth);
        glTextureStorage2D(m.vis_color, 1, GL_RGBA8, view.width, view.height);
        glTextureStorage2D(m.vis_depth, 1, GL_DEPTH_COMPONENT32F, view.width, view.height);
        glNamedFramebufferTexture(m.vis_fbo, GL_COLOR_ATTACHMENT0, m.vis_color, 0);
        glNamedFramebufferTexture(m.vis_fbo, GL_DEPTH_ATTACHMENT, m.vis_depth, 0);
        const GLenum draw_buffers[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
        glNamedFramebufferDrawBuffers(m.vis_fbo, 2, draw_buffers);
        const GLenum status = glCheckNamedFramebufferStatus(m.vis_fbo, GL_DRAW_FRAMEBUFFER);
        if (status != GL_FRAMEBUFFER_COMPLETE) throw Error("GL: status framebuffer incomplete (" + hex(status) + ")");
        m.vis_width = view.width;
        m.vis_height = view.height;
    }
    const Mat4 object_to_clip = view.projection * view.view;
    const int level = m.set_draw_uniforms(view, object_to_clip, sh::kColorStatus);
    m.begin_target(m.vis_fbo, m.vis_width, m.vis_height);
    m.draw_occluders();
    m.draw_patches(level, 0u, 0u);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glProgramUniform1ui(m.draw_program, m.draw_loc.color_mode, sh::kColorPatch);
    std::vector<std::uint8_t> rgba(static_cast<std::size_t>(m.vis_width) * m.vis_height * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureImage(m.vis_color, 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(rgba.size()), rgba.data());
    check_gl("render_status_image");
    return flip_rows(rgba, m.vis_width, m.vis_height, 4);
}

void PatchRenderer::write_status_png(const std::string& path, const RenderParams& view) {
    const std::vector<std::uint8_t> rgba = render_status_image(view);
    write_png_file(path, view.width, view.height, 4, rgba.data(), view.width * 4);
}

// ---- verification -----------------------------------------------------------------------------

FrameComparison compare_frames(const FrameCapture& reference, const FrameCapture& culled) {
    const std::size_t n = reference.ids.size();
    if (reference.depth.size() != n || culled.ids.size() != n || culled.depth.size() != n)
        throw Error("compare_frames: id and depth buffers of different sizes");
    if (reference.patches.size() != culled.patches.size())
        throw Error("compare_frames: the frames have different patch counts");
    FrameComparison c;
    auto is_patch = [](std::uint32_t id) { return id != sh::kIdBackground && !(id & sh::kIdOccluderBit); };
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t a = reference.ids[i], b = culled.ids[i];
        if (a == b) continue;
        ++c.differing_pixels;
        if (is_patch(a) && is_patch(b) && reference.depth[i] == culled.depth[i]) ++c.depth_ties;
    }
    // A false cull is decided per patch, never per pixel: culled (not drawn) here and at the front
    // of the reference somewhere. The front set includes the losers of depth ties, so a tie
    // cannot hide a culled patch.
    for (std::size_t p = 0; p < reference.patches.size(); ++p)
        if (reference.patches[p] && !culled.patches[p]) c.false_culled.push_back(static_cast<std::uint32_t>(p));
    return c;
}

// ---- names ------------------------------------------------------------------------------------

const char* cull_mode_name(CullMode mode) {
    switch (mode) {
        case CullMode::none: return "none";
        case CullMode::frustum: return "frustum";
        case CullMode::backpatch: return "backpatch";
        case CullMode::occlusion: return "occlusion";
        case CullMode::all: return "all";
    }
    return "?";
}

bool parse_cull_mode(const char* text, CullMode& mode) {
    if (!text) return false;
    for (CullMode m : {CullMode::none, CullMode::frustum, CullMode::backpatch, CullMode::occlusion, CullMode::all})
        if (std::strcmp(text, cull_mode_name(m)) == 0) {
            mode = m;
            return true;
        }
    return false;
}

const char* timing_method_name(TimingMethod method) {
    switch (method) {
        case TimingMethod::automatic: return "automatic";
        case TimingMethod::wall_clock: return "wall-clock";
        case TimingMethod::timer_query: return "timer-query";
        case TimingMethod::off: return "off";
    }
    return "?";
}

}  // namespace patchcull::gl
