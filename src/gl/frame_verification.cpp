// PatchRenderer's status image (Niessner & Loop, Fig. 2's statuses; patchcull/gl/gl_renderer.h), the
// comparison of a culled frame with its unculled reference and the id image (compare_frames,
// write_ids_png: patchcull/gl/gl_verification.h), and the cull-mode and timing names
// (gl_cull_flags.h, gl_pipeline.h).
#include <epoxy/gl.h>

#include <cstring>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_renderer.h"
#include "patchcull/gl/gl_verification.h"
#include "renderer_internal.h"

namespace patchcull::gl {

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
    m.draw_occluders(false);
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

void write_ids_png(const std::string& path, const std::vector<std::uint32_t>& ids, int width, int height) {
    if (width < 1 || height < 1 || ids.size() != static_cast<std::size_t>(width) * height)
        throw Error(path + ": cannot write PNG: id buffer is not width x height");
    std::vector<std::uint8_t> rgb(ids.size() * 3);
    for (std::size_t i = 0; i < ids.size(); ++i) {
        std::uint32_t h = ids[i] * 0x9E3779B9u;
        h ^= h >> 16;
        h *= 0x85EBCA6Bu;
        h ^= h >> 13;
        for (int c = 0; c < 3; ++c)
            rgb[3 * i + c] = ids[i] == sh::kIdBackground ? 0 : static_cast<std::uint8_t>(64 + ((h >> (8 * c)) & 191));
    }
    write_png_file(path, width, height, 3, rgb.data(), width * 3);
}

// ---- names ------------------------------------------------------------------------------------

const char* cull_mode_name(CullMode mode) {
    switch (mode) {
        case CullMode::none:
            return "none";
        case CullMode::frustum:
            return "frustum";
        case CullMode::backpatch:
            return "backpatch";
        case CullMode::occlusion:
            return "occlusion";
        case CullMode::all:
            return "all";
    }
    return "?";
}

bool parse_cull_mode(const char* text, CullMode& mode) {
    if (!text) return false;
    for (CullMode m : kCullModes)
        if (std::strcmp(text, cull_mode_name(m)) == 0) {
            mode = m;
            return true;
        }
    return false;
}

const char* timing_method_name(TimingMethod method) {
    switch (method) {
        case TimingMethod::automatic:
            return "automatic";
        case TimingMethod::wall_clock:
            return "wall-clock";
        case TimingMethod::timer_query:
            return "timer-query";
        case TimingMethod::off:
            return "off";
    }
    return "?";
}

}  // namespace patchcull::gl
