// PatchRenderer (patchcull/gl/gl_renderer.h): buffers, programs, the tessellated draw into an
// off-screen framebuffer, triangle occluders, the status image and read-backs. GL 4.5 direct
// state access. It draws only: the cull passes are gl_passes.h's, chained by CullPipeline
// (cull_pipeline.cpp). The shared internals are in renderer_internal.h.
#include <epoxy/gl.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_renderer.h"
#include "renderer_internal.h"

namespace patchcull::gl {

PatchRenderer::PatchRenderer(const GlContext& ctx) : impl_(std::make_unique<Impl>()) {
    ctx.make_current();
    if (epoxy_gl_version() < 45) throw Error("GL: PatchRenderer needs OpenGL 4.5 (context has " + ctx.version() + ")");
    Impl& m = *impl_;
    const std::vector<std::pair<const char*, GLenum>> patch_stages = {{"patch.vert.glsl", GL_VERTEX_SHADER},
                                                                      {"patch.tesc.glsl", GL_TESS_CONTROL_SHADER},
                                                                      {"patch.tese.glsl", GL_TESS_EVALUATION_SHADER},
                                                                      {"patch.frag.glsl", GL_FRAGMENT_SHADER}};
    m.draw_program = link_program(patch_stages, "patch");
    m.mark_program = link_program(patch_stages, "patch (mark front)", "#define PATCHCULL_MARK_FRONT 1\n");
    m.list_program = link_program(patch_stages, "patch (draw list)", "#define PATCHCULL_DRAW_LIST 1\n");
    m.draw_loc.locate(m.draw_program);
    m.mark_loc.locate(m.mark_program);
    m.list_loc.locate(m.list_program);
    m.indirect_count_arb = epoxy_has_gl_extension("GL_ARB_indirect_parameters");
    m.indirect_count = m.indirect_count_arb || epoxy_gl_version() >= 46;
    m.occluder_program = link_program(
        {{"occluder.vert.glsl", GL_VERTEX_SHADER}, {"occluder.frag.glsl", GL_FRAGMENT_SHADER}}, "occluder");
    m.occluder_loc = {glGetUniformLocation(m.occluder_program, "u_object_to_clip"),
                      glGetUniformLocation(m.occluder_program, "u_eye")};

    glCreateVertexArrays(1, &m.vao);
    GLuint buffers[10];
    glCreateBuffers(10, buffers);
    m.control_points = buffers[0];
    m.cull_flags = buffers[1];
    m.max_displacement = buffers[2];
    m.texcoords = buffers[3];
    m.ranges = buffers[4];
    m.occluder_vertices = buffers[5];
    m.tangents = buffers[6];
    m.drawn_marks = buffers[7];
    m.front_marks = buffers[8];
    m.tess_scale = buffers[9];
    upload(m.occluder_vertices, 0, nullptr);
    glCreateFramebuffers(1, &m.fbo);
    glCreateFramebuffers(1, &m.vis_fbo);
    m.set_patches(nullptr, 0, {});
    set_displacement_map(DisplacementMap{});
    m.resize(256, 256);
    check_gl("PatchRenderer setup");
}

PatchRenderer::PatchRenderer(PatchRenderer&&) noexcept = default;
PatchRenderer& PatchRenderer::operator=(PatchRenderer&&) noexcept = default;
PatchRenderer::~PatchRenderer() = default;

namespace {

// The bytes Impl::set_patches (renderer_internal.h) copies to GL for n patches: control points,
// margins (given, or the ranges' max |D|), ranges, corner texcoords (always, defaults included),
// tangents (24 vec4 per patch, or a 16-byte placeholder) and tessellation scales (at least one).
// Flags and marks are cleared or allocated on the GPU, not copied.
std::size_t patch_upload_bytes(std::size_t n, const PatchAttributes& a) {
    const bool margins = !a.max_displacement.empty() || !a.displacement_ranges.empty();
    return n * sizeof(BezierPatch) + (margins ? n * sizeof(float) : 0) +
           (a.displacement_ranges.empty() ? 0 : n * sizeof(DisplacementRange)) + n * 4 * sizeof(Vec2) +
           (a.tangent_index.empty() ? sizeof(Vec4) : n * sh::kTangentVec4s * sizeof(Vec4)) +
           std::max<std::size_t>(n, 1) * sizeof(float);
}

}  // namespace

void PatchRenderer::set_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes) {
    last_upload_bytes_ = patch_upload_bytes(patches.size(), attributes);
    static_assert(sizeof(BezierPatch) == kPatchPoints * 4 * sizeof(float), "BezierPatch must be 16 packed float4");
    impl_->set_patches(patches.empty() ? nullptr : &patches[0].cp[0].x, patches.size(), attributes);
}

void PatchRenderer::set_patches(const PatchBatchView& patches, const PatchAttributes& attributes) {
    std::vector<float> aos(patches.count * kPatchPoints * 4);
    for (std::size_t p = 0; p < patches.count; ++p)
        for (int k = 0; k < kPatchPoints; ++k)
            for (int c = 0; c < 4; ++c) aos[(p * kPatchPoints + k) * 4 + c] = patches.component(k, c)[p];
    impl_->set_patches(aos.data(), patches.count, attributes);
    last_upload_bytes_ = patch_upload_bytes(patches.count, attributes);
}

void PatchRenderer::update_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes) {
    impl_->set_patches(patches.empty() ? nullptr : &patches[0].cp[0].x, patches.size(), attributes, true);
    last_upload_bytes_ = patch_upload_bytes(patches.size(), attributes);
}

std::size_t PatchRenderer::patch_count() const { return impl_->count; }
std::uint32_t PatchRenderer::patch_buffer() const { return impl_->control_points; }
std::uint32_t PatchRenderer::flag_buffer() const { return impl_->cull_flags; }
std::uint32_t PatchRenderer::margin_buffer() const { return impl_->has_max_displacement ? impl_->max_displacement : 0; }
std::uint32_t PatchRenderer::range_buffer() const { return impl_->has_ranges ? impl_->ranges : 0; }
const std::vector<PatchSpan>& PatchRenderer::undisplaced_runs() const { return impl_->runs.undisplaced; }
const std::vector<PatchSpan>& PatchRenderer::displaced_runs() const { return impl_->runs.displaced; }
std::uint32_t PatchRenderer::depth_texture() const { return impl_->depth; }
std::uint32_t PatchRenderer::tangent_buffer() const { return impl_->tangents; }
std::size_t PatchRenderer::last_upload_bytes() const { return last_upload_bytes_; }
PatchBuffers PatchRenderer::patch_buffers() const {
    return {impl_->control_points, impl_->cull_flags, margin_buffer(), 0, impl_->count};
}
bool PatchRenderer::displaces() const { return impl_->has_displacement_map; }
std::uint64_t PatchRenderer::flag_generation() const { return impl_->flag_generation; }

void PatchRenderer::set_displacement_map(const DisplacementMap& map) {
    Impl& m = *impl_;
    glDeleteTextures(1, &m.displacement_texture);
    glCreateTextures(GL_TEXTURE_2D, 1, &m.displacement_texture);
    const bool has = !map.empty();
    if (has && map.texels.size() != static_cast<std::size_t>(map.width) * map.height)
        throw Error("GL: set_displacement_map: texel count does not match width x height");
    const int w = has ? map.width : 1, h = has ? map.height : 1;
    const float zero = 0.0f;
    glTextureStorage2D(m.displacement_texture, 1, GL_R32F, w, h);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(m.displacement_texture, 0, 0, 0, w, h, GL_RED, GL_FLOAT, has ? map.texels.data() : &zero);
    glTextureParameteri(m.displacement_texture, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTextureParameteri(m.displacement_texture, GL_TEXTURE_WRAP_T, GL_REPEAT);
    glTextureParameteri(m.displacement_texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(m.displacement_texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    m.has_displacement_map = has;
    m.displacement_scale = has ? map.scale : 0.0f;
    m.displacement_midlevel = map.midlevel;
    check_gl("set_displacement_map");
}

void PatchRenderer::clear_cull_flags() {
    glClearNamedBufferData(impl_->cull_flags, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    ++impl_->flag_generation;
    check_gl("clear_cull_flags");
}

void PatchRenderer::set_cull_flags(const std::uint8_t* culled) {
    std::vector<std::uint32_t> flags(impl_->count);
    for (std::size_t p = 0; p < flags.size(); ++p) flags[p] = culled[p] ? sh::kCullFrustum : 0u;
    ++impl_->flag_generation;
    if (!flags.empty())
        glNamedBufferSubData(impl_->cull_flags, 0, static_cast<GLsizeiptr>(flags.size() * sizeof(std::uint32_t)),
                             flags.data());
    check_gl("set_cull_flags");
}

std::vector<std::uint32_t> PatchRenderer::read_cull_flags() const {
    std::vector<std::uint32_t> flags(impl_->count);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    if (!flags.empty())
        glGetNamedBufferSubData(impl_->cull_flags, 0, static_cast<GLsizeiptr>(flags.size() * sizeof(std::uint32_t)),
                                flags.data());
    check_gl("read_cull_flags");
    return flags;
}

void PatchRenderer::set_flag_words(const std::vector<std::uint32_t>& words) {
    if (words.size() != impl_->count)
        throw Error("GL: set_flag_words: " + std::to_string(words.size()) + " words for " +
                    std::to_string(impl_->count) + " patches");
    if (!words.empty())
        glNamedBufferSubData(impl_->cull_flags, 0, static_cast<GLsizeiptr>(words.size() * sizeof(std::uint32_t)),
                             words.data());
    ++impl_->flag_generation;
    check_gl("set_flag_words");
}

void PatchRenderer::render(const RenderParams& params) {
    begin_frame_drawing(params, params.use_cull_flags);
    draw_selected(params.use_cull_flags ? sh::kDrawMaskUnculled : 0u,
                  params.use_cull_flags ? sh::kDrawValueUnculled : 0u);
}

void PatchRenderer::begin_frame(const RenderParams& params) { begin_frame_drawing(params, true); }

void PatchRenderer::begin_frame_drawing(const RenderParams& params, bool honour_occluder_culls) {
    Impl& m = *impl_;
    m.resize(params.width, params.height);
    const Mat4 object_to_clip = params.projection * params.view;
    m.frame_level = m.set_draw_uniforms(params, object_to_clip, sh::kColorPatch, true);
    m.begin_target(m.fbo, m.width, m.height);
    m.draw_occluders(honour_occluder_culls);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    check_gl("begin_frame");
}

void PatchRenderer::begin_depth_test_draws() {
    Impl& m = *impl_;
    m.bind_target(m.fbo, m.width, m.height);
    glDepthFunc(m.depth_less(true));
    glDepthMask(GL_FALSE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    check_gl("begin_depth_test_draws");
}

void PatchRenderer::end_depth_test_draws() {
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glDepthFunc(impl_->depth_less());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    check_gl("end_depth_test_draws");
}

void PatchRenderer::draw_selected(std::uint32_t mask, std::uint32_t value) {
    Impl& m = *impl_;
    m.bind_target(m.fbo, m.width, m.height);
    m.draw_patches(m.frame_level, mask, value);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    check_gl("draw_selected");
}

void PatchRenderer::draw_selected(std::uint32_t mask, std::uint32_t value, const std::vector<PatchSpan>& spans) {
    Impl& m = *impl_;
    std::vector<PatchSpan> sorted = spans;
    std::sort(sorted.begin(), sorted.end(), [](const PatchSpan& a, const PatchSpan& b) { return a.first < b.first; });
    std::size_t covered = 0;
    for (const PatchSpan& s : sorted) {
        if (s.first > m.count || s.count > m.count - s.first)
            throw Error("GL: draw_selected: span [" + std::to_string(s.first) + ", +" + std::to_string(s.count) +
                        ") leaves the set of " + std::to_string(m.count) + " patches");
        if (s.first < covered) throw Error("GL: draw_selected: spans overlap at patch " + std::to_string(s.first));
        covered = s.first + s.count;
    }
    m.bind_target(m.fbo, m.width, m.height);
    m.draw_patches(m.frame_level, mask, value, false, &sorted);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    check_gl("draw_selected");
}

std::size_t PatchRenderer::patches_per_draw() const { return impl_->patches_per_draw(impl_->frame_level); }
bool PatchRenderer::has_indirect_count() const { return impl_->indirect_count; }

void PatchRenderer::draw_indirect(const IndirectDraw& draw) {
    Impl& m = *impl_;
    if (!draw.list || !draw.commands) throw Error("GL: draw_indirect: the list and the command buffer are required");
    GLint64 bytes = 0;
    glGetNamedBufferParameteri64v(draw.commands, GL_BUFFER_SIZE, &bytes);
    if ((draw.first_command + draw.command_count) * 16 > static_cast<std::size_t>(std::max<GLint64>(bytes, 0)))
        throw Error("GL: draw_indirect: commands [" + std::to_string(draw.first_command) + ", +" +
                    std::to_string(draw.command_count) + ") leave the command buffer of " + std::to_string(bytes) +
                    " bytes");
    if (draw.draw_count_offset % 4 != 0)
        throw Error("GL: draw_indirect: draw-count offset " + std::to_string(draw.draw_count_offset) +
                    " is not a multiple of 4");
    m.bind_target(m.fbo, m.width, m.height);
    m.draw_list(draw);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    check_gl("draw_indirect");
}

namespace {

std::vector<std::uint8_t> read_marks(GLuint buffer, std::size_t count) {
    std::vector<std::uint32_t> words(count);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    if (count) glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(count * sizeof(std::uint32_t)), words.data());
    check_gl("read patch marks");
    std::vector<std::uint8_t> marks(count);
    for (std::size_t p = 0; p < count; ++p) marks[p] = words[p] != 0;
    return marks;
}

}  // namespace

std::vector<std::uint8_t> PatchRenderer::read_drawn_patches() const {
    return read_marks(impl_->drawn_marks, impl_->count);
}

std::vector<std::uint8_t> PatchRenderer::mark_front_patches(const RenderParams& params) {
    Impl& m = *impl_;
    if (params.width != m.width || params.height != m.height)
        throw Error("GL: mark_front_patches: params are not the last render's size");
    if (m.count == 0) return {};
    const Mat4 object_to_clip = params.projection * params.view;
    const int level = m.set_draw_uniforms(params, object_to_clip, sh::kColorPatch);
    glClearNamedBufferData(m.front_marks, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    m.bind_target(m.fbo, m.width, m.height);
    // The mark-front pass: fragments exactly at the front depth, nothing written.
    glDepthFunc(GL_EQUAL);
    glDepthMask(GL_FALSE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    m.draw_patches(level, params.use_cull_flags ? sh::kCullReasonMask : 0u, 0u, true);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glDepthFunc(m.depth_less());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    check_gl("mark_front_patches");
    return read_marks(m.front_marks, m.count);
}

// ---- occluders ---------------------------------------------------------------------------------

namespace {

// Sets flags[t] = 1 for the triangles of spans (each within triangles, else throws naming what).
void mark_triangle_spans(const std::vector<TriangleSpan>& spans, std::size_t triangles, const char* what,
                         std::vector<std::uint8_t>& flags) {
    flags.assign(triangles, 0);
    for (const TriangleSpan& s : spans) {
        if (s.first > triangles || s.count > triangles - s.first)
            throw Error(std::string("GL: ") + what + ": triangle span [" + std::to_string(s.first) + ", +" +
                        std::to_string(s.count) + ") leaves the " + std::to_string(triangles) + " occluder triangles");
        std::fill(flags.begin() + static_cast<std::ptrdiff_t>(s.first),
                  flags.begin() + static_cast<std::ptrdiff_t>(s.first + s.count), std::uint8_t{1});
    }
}

}  // namespace

void PatchRenderer::set_culled_occluders(const std::vector<TriangleSpan>& culled) {
    mark_triangle_spans(culled, impl_->occluder_triangles, "set_culled_occluders", impl_->occluder_culled);
}

void PatchRenderer::set_occluders(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& indices,
                                  const std::vector<TriangleSpan>& one_sided) {
    if (indices.size() % 3 != 0)
        throw Error("GL: set_occluders: " + std::to_string(indices.size()) + " indices is not a multiple of 3");
    if (indices.size() / 3 >= 0x80000000u) throw Error("GL: set_occluders: 2^31 triangles or more");
    std::vector<float> expanded(indices.size() * 4);
    for (std::size_t i = 0; i < indices.size(); ++i) {
        if (indices[i] >= vertices.size())
            throw Error("GL: set_occluders: index " + std::to_string(indices[i]) + " out of range (" +
                        std::to_string(vertices.size()) + " vertices)");
        const Vec3 v = vertices[indices[i]];
        expanded[4 * i] = v.x;
        expanded[4 * i + 1] = v.y;
        expanded[4 * i + 2] = v.z;
        expanded[4 * i + 3] = 1.0f;
    }
    std::vector<std::uint8_t> sides;
    mark_triangle_spans(one_sided, indices.size() / 3, "set_occluders", sides);
    upload(impl_->occluder_vertices, expanded.size() * sizeof(float), expanded.data());
    impl_->occluder_triangles = indices.size() / 3;
    impl_->occluder_one_sided = std::move(sides);
    impl_->occluder_culled.assign(impl_->occluder_triangles, 0);
    check_gl("set_occluders");
}

std::size_t PatchRenderer::occluder_triangle_count() const { return impl_->occluder_triangles; }

void PatchRenderer::finish() const { glFinish(); }

int PatchRenderer::width() const { return impl_->width; }
int PatchRenderer::height() const { return impl_->height; }

std::vector<std::uint32_t> PatchRenderer::read_ids() const {
    const Impl& m = *impl_;
    std::vector<std::uint32_t> ids(static_cast<std::size_t>(m.width) * m.height);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureImage(m.ids, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, static_cast<GLsizei>(ids.size() * 4), ids.data());
    check_gl("read_ids");
    return flip_rows(ids, m.width, m.height, 1);
}

std::vector<float> PatchRenderer::read_depth_bottom_up() const {
    const Impl& m = *impl_;
    std::vector<float> depth(static_cast<std::size_t>(m.width) * m.height);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureImage(m.depth, 0, GL_DEPTH_COMPONENT, GL_FLOAT, static_cast<GLsizei>(depth.size() * 4), depth.data());
    check_gl("read_depth");
    return depth;  // a texture's row 0 is the bottom row
}

std::vector<float> PatchRenderer::read_depth() const {
    return flip_rows(read_depth_bottom_up(), impl_->width, impl_->height, 1);
}

std::vector<std::uint8_t> PatchRenderer::read_color() const {
    const Impl& m = *impl_;
    std::vector<std::uint8_t> rgba(static_cast<std::size_t>(m.width) * m.height * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureImage(m.color, 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(rgba.size()), rgba.data());
    check_gl("read_color");
    return flip_rows(rgba, m.width, m.height, 4);
}

void PatchRenderer::blit_color_to_window(int window_width, int window_height) const {
    const Impl& m = *impl_;
    glNamedFramebufferReadBuffer(m.fbo, GL_COLOR_ATTACHMENT0);
    glBlitNamedFramebuffer(m.fbo, 0, 0, 0, m.width, m.height, 0, 0, window_width, window_height, GL_COLOR_BUFFER_BIT,
                           GL_NEAREST);
    check_gl("blit to window");
}

void PatchRenderer::write_color_png(const std::string& path) const {
    const std::vector<std::uint8_t> rgba = read_color();
    write_png_file(path, impl_->width, impl_->height, 4, rgba.data(), impl_->width * 4);
}

}  // namespace patchcull::gl
