// PatchRenderer (patchcull/gl_renderer.h): buffers, programs, the tessellated draw into an
// off-screen framebuffer, the GPU frustum pass and read-backs. GL 4.5 direct state access.
#include <epoxy/gl.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "patchcull/error.h"
#include "patchcull/gl_renderer.h"
#include "shader_sources.h"
#include "shared.h"

namespace patchcull::gl {

namespace {

namespace sh = shared;

std::string hex(unsigned value) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", value);
    return buf;
}

void check_gl(const char* where) {
    const GLenum e = glGetError();
    if (e == GL_NO_ERROR) return;
    while (glGetError() != GL_NO_ERROR) {
    }
    throw Error("GL: error " + hex(e) + " after " + where);
}

std::string first_line(std::string log) {
    while (!log.empty() && (log.back() == '\n' || log.back() == '\r' || log.back() == ' ')) log.pop_back();
    const std::size_t nl = log.find('\n');
    if (nl != std::string::npos) log = log.substr(0, nl) + " (...)";
    return log;
}

// Compiles embedded shader name with `defines` (lines "#define X 1\n") inserted after #version.
GLuint compile_shader(const char* name, GLenum stage, const std::string& defines) {
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

GLuint link_program(const std::vector<std::pair<const char*, GLenum>>& stages, const char* label,
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
void upload(GLuint buffer, std::size_t size, const void* data) {
    glNamedBufferData(buffer, static_cast<GLsizeiptr>(std::max<std::size_t>(size, 16)), nullptr, GL_DYNAMIC_DRAW);
    if (size && data) glNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(size), data);
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

}  // namespace

struct PatchRenderer::Impl {
    GLuint vao = 0;
    GLuint draw_program = 0, frustum_program = 0;
    GLuint control_points = 0, cull_flags = 0, max_displacement = 0, texcoords = 0, plane_values = 0;
    GLuint displacement_texture = 0;
    float displacement_scale = 0, displacement_midlevel = 0.5f;
    bool has_displacement_map = false;
    bool has_max_displacement = false;
    bool fma_via_double = false;
    GLuint fbo = 0, color = 0, ids = 0, depth = 0;
    int width = 0, height = 0;
    std::size_t count = 0;

    struct {
        GLint tess_level, use_cull_flags, object_to_clip, displace, displacement_scale, displacement_midlevel, eye;
    } draw_loc{};
    struct {
        GLint rows, normal_length, patch_count, has_displacement, write_plane_values;
    } frustum_loc{};

    ~Impl() {
        glDeleteProgram(draw_program);
        glDeleteProgram(frustum_program);
        const GLuint buffers[] = {control_points, cull_flags, max_displacement, texcoords, plane_values};
        glDeleteBuffers(5, buffers);
        const GLuint textures[] = {displacement_texture, color, ids, depth};
        glDeleteTextures(4, textures);
        glDeleteFramebuffers(1, &fbo);
        glDeleteVertexArrays(1, &vao);
    }

    void link_cull_programs() {
        glDeleteProgram(frustum_program);
        const std::string defines = fma_via_double ? "#define PATCHCULL_FMA_VIA_DOUBLE 1\n" : "";
        frustum_program = link_program({{"cull_frustum.comp.glsl", GL_COMPUTE_SHADER}}, "cull_frustum", defines);
        const GLuint fp = frustum_program;
        frustum_loc = {glGetUniformLocation(fp, "u_plane_rows"), glGetUniformLocation(fp, "u_plane_normal_length"),
                       glGetUniformLocation(fp, "u_patch_count"), glGetUniformLocation(fp, "u_has_displacement"),
                       glGetUniformLocation(fp, "u_write_plane_values")};
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
    }

    void set_patches(const float* aos_points, std::size_t n, const PatchAttributes& a) {
        if (!a.max_displacement.empty() && a.max_displacement.size() != n)
            throw Error("GL: set_patches: max_displacement has " + std::to_string(a.max_displacement.size()) +
                        " entries for " + std::to_string(n) + " patches");
        if (!a.texcoords.empty() && a.texcoords.size() != n)
            throw Error("GL: set_patches: texcoords has " + std::to_string(a.texcoords.size()) + " entries for " +
                        std::to_string(n) + " patches");
        if (n > 0x7FFFFFFFu / kPatchPoints) throw Error("GL: set_patches: too many patches for one draw (" + std::to_string(n) + ")");
        count = n;
        upload(control_points, n * kPatchPoints * 4 * sizeof(float), aos_points);
        upload(cull_flags, n * sizeof(std::uint32_t), nullptr);
        glClearNamedBufferData(cull_flags, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
        has_max_displacement = !a.max_displacement.empty();
        upload(max_displacement, has_max_displacement ? n * sizeof(float) : 0, a.max_displacement.data());
        std::vector<Vec2> uv(4 * n);
        for (std::size_t p = 0; p < n; ++p)
            for (int c = 0; c < 4; ++c)
                uv[4 * p + c] = a.texcoords.empty() ? Vec2{float(c & 1), float(c >> 1)} : a.texcoords[p][c];
        upload(texcoords, uv.size() * sizeof(Vec2), uv.data());
        upload(plane_values, 0, nullptr);
        check_gl("set_patches");
    }
};

PatchRenderer::PatchRenderer(const GlContext& ctx) : impl_(std::make_unique<Impl>()) {
    ctx.make_current();
    if (epoxy_gl_version() < 45) throw Error("GL: PatchRenderer needs OpenGL 4.5 (context has " + ctx.version() + ")");
    Impl& m = *impl_;
    m.draw_program = link_program({{"patch.vert.glsl", GL_VERTEX_SHADER},
                                   {"patch.tesc.glsl", GL_TESS_CONTROL_SHADER},
                                   {"patch.tese.glsl", GL_TESS_EVALUATION_SHADER},
                                   {"patch.frag.glsl", GL_FRAGMENT_SHADER}},
                                  "patch");
    // Mesa's software rasterizers round GLSL fma() twice; the cull passes then compute it exactly
    // in double precision (shaders/exact_fma.h) so that decisions equal the CPU kernels'. On other
    // drivers native fma() is checked once below.
    m.fma_via_double = ctx.is_software();
    m.link_cull_programs();
    const GLuint dp = m.draw_program;
    m.draw_loc = {glGetUniformLocation(dp, "u_tess_level"),         glGetUniformLocation(dp, "u_use_cull_flags"),
                  glGetUniformLocation(dp, "u_object_to_clip"),     glGetUniformLocation(dp, "u_displace"),
                  glGetUniformLocation(dp, "u_displacement_scale"), glGetUniformLocation(dp, "u_displacement_midlevel"),
                  glGetUniformLocation(dp, "u_eye")};

    glCreateVertexArrays(1, &m.vao);
    GLuint buffers[5];
    glCreateBuffers(5, buffers);
    m.control_points = buffers[0];
    m.cull_flags = buffers[1];
    m.max_displacement = buffers[2];
    m.texcoords = buffers[3];
    m.plane_values = buffers[4];
    glCreateFramebuffers(1, &m.fbo);
    m.set_patches(nullptr, 0, {});
    set_displacement_map(DisplacementMap{});
    m.resize(256, 256);
    check_gl("PatchRenderer setup");
    if (!m.fma_via_double && !native_fma_rounds_once()) {
        m.fma_via_double = true;
        m.link_cull_programs();
    }
}

// Start-up check of GLSL fma() on a GPU: hand-made planes make the frustum pass report exactly
// fma(a, b, c) for cases where a*b + c lies just off the midpoint between two floats, so that any
// second rounding (through float or double) gives the wrong neighbour (tests/gl frustum_gpu_test
// does the same on more cases).
bool PatchRenderer::native_fma_rounds_once() {
    const float a = std::ldexp(1.0f + std::ldexp(1.0f, -23), -24);
    const float b = 1.0f - std::ldexp(1.0f, -23);
    const float c = 1.0f + std::ldexp(1.0f, -23);
    const float a_values[6] = {a, -a, 2 * a, a / 2, -2 * a, 0.75f};
    FrustumPlanes planes;
    for (int q = 0; q < 6; ++q) {
        planes.rows[q] = {1, 0, 0, a_values[q]};
        planes.normal_length[q] = 0;
    }
    const float bc[4][2] = {{b, c}, {b, -c}, {-b, -c}, {std::ldexp(b, 9), std::ldexp(c, 9)}};
    std::vector<BezierPatch> probe(4);
    for (int p = 0; p < 4; ++p)
        for (Vec4& cp : probe[p].cp) cp = {bc[p][1], 0, 0, bc[p][0]};
    set_patches(probe);
    std::vector<float> values;
    cull_frustum(planes, &values);
    set_patches(std::vector<BezierPatch>{});
    for (int p = 0; p < 4; ++p)
        for (int q = 0; q < 6; ++q)
            if (values[6 * p + q] != std::fma(a_values[q], bc[p][0], bc[p][1])) return false;
    return true;
}

PatchRenderer::PatchRenderer(PatchRenderer&&) noexcept = default;
PatchRenderer& PatchRenderer::operator=(PatchRenderer&&) noexcept = default;
PatchRenderer::~PatchRenderer() = default;

void PatchRenderer::set_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes) {
    static_assert(sizeof(BezierPatch) == kPatchPoints * 4 * sizeof(float), "BezierPatch must be 16 packed float4");
    impl_->set_patches(patches.empty() ? nullptr : &patches[0].cp[0].x, patches.size(), attributes);
}

void PatchRenderer::set_patches(const PatchBatchView& patches, const PatchAttributes& attributes) {
    std::vector<float> aos(patches.count * kPatchPoints * 4);
    for (std::size_t p = 0; p < patches.count; ++p)
        for (int k = 0; k < kPatchPoints; ++k)
            for (int c = 0; c < 4; ++c) aos[(p * kPatchPoints + k) * 4 + c] = patches.component(k, c)[p];
    impl_->set_patches(aos.data(), patches.count, attributes);
}

std::size_t PatchRenderer::patch_count() const { return impl_->count; }
bool PatchRenderer::fma_via_double() const { return impl_->fma_via_double; }

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
    check_gl("clear_cull_flags");
}

void PatchRenderer::set_cull_flags(const std::uint8_t* culled) {
    std::vector<std::uint32_t> flags(impl_->count);
    for (std::size_t p = 0; p < flags.size(); ++p) flags[p] = culled[p] ? sh::kCullFrustum : 0u;
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

void PatchRenderer::cull_frustum(const FrustumPlanes& planes, std::vector<float>* plane_values) {
    Impl& m = *impl_;
    if (m.count == 0) {
        if (plane_values) plane_values->clear();
        return;
    }
    const std::size_t groups = (m.count + sh::kCullGroupSize - 1) / sh::kCullGroupSize;
    if (groups > 65535) throw Error("GL: cull_frustum: more than 65535 * 64 patches");
    if (plane_values) upload(m.plane_values, 6 * m.count * sizeof(float), nullptr);
    const GLuint fp = m.frustum_program;
    glProgramUniform4fv(fp, m.frustum_loc.rows, 6, &planes.rows[0].x);
    glProgramUniform1fv(fp, m.frustum_loc.normal_length, 6, planes.normal_length);
    glProgramUniform1ui(fp, m.frustum_loc.patch_count, static_cast<GLuint>(m.count));
    glProgramUniform1i(fp, m.frustum_loc.has_displacement, m.has_max_displacement ? 1 : 0);
    glProgramUniform1i(fp, m.frustum_loc.write_plane_values, plane_values ? 1 : 0);
    glUseProgram(fp);
    m.bind_buffers();
    glDispatchCompute(static_cast<GLuint>(groups), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glUseProgram(0);
    if (plane_values) {
        plane_values->resize(6 * m.count);
        glGetNamedBufferSubData(m.plane_values, 0, static_cast<GLsizeiptr>(plane_values->size() * sizeof(float)),
                                plane_values->data());
        upload(m.plane_values, 0, nullptr);
    }
    check_gl("cull_frustum");
}

void PatchRenderer::render(const RenderParams& params) {
    Impl& m = *impl_;
    m.resize(params.width, params.height);
    const int level = std::clamp(params.tess_level, 1, 64);
    const Mat4 object_to_clip = params.projection * params.view;
    Mat4 view_inverse;
    Vec3 eye{0, 0, 0};
    if (invert(params.view, view_inverse)) eye = {view_inverse.at(0, 3), view_inverse.at(1, 3), view_inverse.at(2, 3)};

    const GLuint dp = m.draw_program;
    glProgramUniform1f(dp, m.draw_loc.tess_level, static_cast<float>(level));
    glProgramUniform1i(dp, m.draw_loc.use_cull_flags, params.use_cull_flags ? 1 : 0);
    glProgramUniformMatrix4fv(dp, m.draw_loc.object_to_clip, 1, GL_FALSE, object_to_clip.m);
    glProgramUniform1i(dp, m.draw_loc.displace, params.displace && m.has_displacement_map ? 1 : 0);
    glProgramUniform1f(dp, m.draw_loc.displacement_scale, m.displacement_scale);
    glProgramUniform1f(dp, m.draw_loc.displacement_midlevel, m.displacement_midlevel);
    glProgramUniform3f(dp, m.draw_loc.eye, eye.x, eye.y, eye.z);

    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, m.fbo);
    glViewport(0, 0, m.width, m.height);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    const float background[4] = {0.12f, 0.12f, 0.14f, 1.0f};
    const GLuint no_id[4] = {sh::kIdBackground, 0, 0, 0};
    const float far_depth = 1.0f;
    glClearNamedFramebufferfv(m.fbo, GL_COLOR, 0, background);
    glClearNamedFramebufferuiv(m.fbo, GL_COLOR, 1, no_id);
    glClearNamedFramebufferfv(m.fbo, GL_DEPTH, 0, &far_depth);

    if (m.count > 0) {
        glUseProgram(dp);
        glBindVertexArray(m.vao);
        m.bind_buffers();
        glBindTextureUnit(sh::kTextureUnitDisplacement, m.displacement_texture);
        glPatchParameteri(GL_PATCH_VERTICES, kPatchPoints);
        // llvmpipe workaround 2 (header): at most 65536 / (L+1)^2 patches per sub-draw.
        const std::size_t per_draw = std::max<std::size_t>(1, 65536 / static_cast<std::size_t>((level + 1) * (level + 1)));
        std::vector<GLint> firsts;
        std::vector<GLsizei> counts;
        for (std::size_t first = 0; first < m.count; first += per_draw) {
            firsts.push_back(static_cast<GLint>(first * kPatchPoints));
            counts.push_back(static_cast<GLsizei>(std::min(per_draw, m.count - first) * kPatchPoints));
        }
        glMultiDrawArrays(GL_PATCHES, firsts.data(), counts.data(), static_cast<GLsizei>(firsts.size()));
        glBindVertexArray(0);
        glUseProgram(0);
    }
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    check_gl("render");
}

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

std::vector<float> PatchRenderer::read_depth() const {
    const Impl& m = *impl_;
    std::vector<float> depth(static_cast<std::size_t>(m.width) * m.height);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureImage(m.depth, 0, GL_DEPTH_COMPONENT, GL_FLOAT, static_cast<GLsizei>(depth.size() * 4), depth.data());
    check_gl("read_depth");
    return flip_rows(depth, m.width, m.height, 1);
}

std::vector<std::uint8_t> PatchRenderer::read_color() const {
    const Impl& m = *impl_;
    std::vector<std::uint8_t> rgba(static_cast<std::size_t>(m.width) * m.height * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureImage(m.color, 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(rgba.size()), rgba.data());
    check_gl("read_color");
    return flip_rows(rgba, m.width, m.height, 4);
}

void PatchRenderer::write_color_png(const std::string& path) const {
    const std::vector<std::uint8_t> rgba = read_color();
    if (!stbi_write_png(path.c_str(), impl_->width, impl_->height, 4, rgba.data(), impl_->width * 4))
        throw Error(path + ": cannot write PNG");
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
    if (!stbi_write_png(path.c_str(), width, height, 3, rgb.data(), width * 3)) throw Error(path + ": cannot write PNG");
}

}  // namespace patchcull::gl
