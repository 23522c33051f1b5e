// PassContext and the helpers of the cull passes (src/gl/pass_common.h, patchcull/gl/gl_passes.h).
#include "pass_common.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

namespace patchcull::gl {

using namespace detail;

// The C++ structs are the GLSL std140 blocks (pass_params.h): sizes a multiple of 16, members in
// std140 order (matrices and vec4 arrays first, then 4-byte scalars).
static_assert(sizeof(pp::FrustumParams) == 4 * 16 + 3 * 16 + 16);
static_assert(sizeof(pp::OcclusionParams) == 4 * 16 + 3 * 16 + 32);
static_assert(sizeof(pp::HiZBuildParams) == 32);
static_assert(sizeof(pp::BackpatchConeParams) == 16 + 32);
static_assert(sizeof(pp::BackpatchPtpParams) == 3 * 16 + 32);
static_assert(sizeof(pp::DisplacedParams) == 64 + 6 * 16 + 3 * 16 + 5 * 16 + 48);
static_assert(sizeof(pp::CullStatusParams) == 16);
static_assert(sizeof(pp::FusedCullParams) == 4 * 16 + 3 * 16 + 16 + 32);
static_assert(offsetof(pp::FusedCullParams, first_patch) == 4 * 16 + 3 * 16 + 16);
static_assert(offsetof(pp::OcclusionParams, first_patch) == 4 * 16 + 3 * 16);
static_assert(offsetof(pp::DisplacedParams, first_patch) == 64 + 6 * 16 + 3 * 16 + 5 * 16);

PassContext::Impl::~Impl() {
    for (const auto& [key, program] : programs) glDeleteProgram(program);
    const GLuint buffers[] = {probe_in, probe_out};
    glDeleteBuffers(2, buffers);
}

GLuint PassContext::Impl::program(const char* shader, const std::string& defines) {
    const std::string all = (fma_via_double ? "#define PATCHCULL_FMA_VIA_DOUBLE 1\n" : "") + defines;
    const std::string key = std::string(shader) + "\n" + all;
    auto it = programs.find(key);
    if (it != programs.end()) return it->second;
    const GLuint p = link_program({{shader, GL_COMPUTE_SHADER}}, shader, all);
    programs.emplace(key, p);
    return p;
}

namespace {

bool renderer_is_software() {
    const char* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    if (!r) return false;
    for (const char* name : {"llvmpipe", "softpipe", "swrast", "Software Rasterizer"})
        if (std::strstr(r, name)) return true;
    return false;
}

}  // namespace

PassContext::PassContext() : impl_(std::make_unique<Impl>()) {
    if (glGetString(GL_VERSION) == nullptr || epoxy_gl_version() < 45)
        throw Error("GL: the cull passes need a current OpenGL 4.5 core context");
    Impl& m = *impl_;
    m.software = renderer_is_software();
    m.fma_via_double = m.software;
    glCreateBuffers(1, &m.probe_in);
    glCreateBuffers(1, &m.probe_out);
    check_gl("PassContext setup");
    if (!m.fma_via_double) {
        // GLSL fma() on a GPU: cases where a*b + c lies just off a midpoint between two floats,
        // so any second rounding gives the other neighbour.
        const float a = std::ldexp(1.0f + std::ldexp(1.0f, -23), -24);
        const float b = 1.0f - std::ldexp(1.0f, -23);
        const float c = 1.0f + std::ldexp(1.0f, -23);
        const float a_values[6] = {a, -a, 2 * a, a / 2, -2 * a, 0.75f};
        const float bc[4][2] = {{b, c}, {b, -c}, {-b, -c}, {std::ldexp(b, 9), std::ldexp(c, 9)}};
        std::vector<Vec3> cases;
        for (const float av : a_values)
            for (const auto& pair : bc) cases.push_back({av, pair[0], pair[1]});
        const std::vector<float> got = probe(BackpatchProbe::fma, cases);
        bool once = true;
        for (std::size_t i = 0; i < cases.size(); ++i)
            once = once && got[i] == std::fma(cases[i].x, cases[i].y, cases[i].z);
        if (!once) {
            for (const auto& [key, program] : m.programs) glDeleteProgram(program);
            m.programs.clear();
            m.fma_via_double = true;
        }
    }
}

PassContext::PassContext(PassContext&&) noexcept = default;
PassContext& PassContext::operator=(PassContext&&) noexcept = default;
PassContext::~PassContext() = default;
bool PassContext::fma_via_double() const { return impl_->fma_via_double; }
bool PassContext::is_software() const { return impl_->software; }
PassContext::Impl& PassContext::impl() { return *impl_; }

std::vector<float> PassContext::probe(BackpatchProbe op, const std::vector<Vec3>& abc) {
    Impl& m = *impl_;
    if (abc.size() > 65535u * shared::kProbeGroupSize) throw Error("GL: probe: too many inputs");
    std::vector<float> in(abc.size() * 4);
    for (std::size_t i = 0; i < abc.size(); ++i) {
        in[4 * i] = abc[i].x;
        in[4 * i + 1] = abc[i].y;
        in[4 * i + 2] = abc[i].z;
    }
    upload(m.probe_in, in.size() * sizeof(float), in.data());
    upload(m.probe_out, abc.size() * sizeof(float), nullptr);
    const GLuint program = m.program("backpatch_probe.comp.glsl");
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingProbeIn, m.probe_in);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingProbeOut, m.probe_out);
    glUniform1ui(glGetUniformLocation(program, "u_count"), static_cast<GLuint>(abc.size()));
    GLuint mode = shared::kProbeFma;
    switch (op) {
        case BackpatchProbe::fma:
            mode = shared::kProbeFma;
            break;
        case BackpatchProbe::div:
            mode = shared::kProbeDiv;
            break;
        case BackpatchProbe::sqrt:
            mode = shared::kProbeSqrt;
            break;
        case BackpatchProbe::div_from:
            mode = shared::kProbeDivFrom;
            break;
        case BackpatchProbe::sqrt_from:
            mode = shared::kProbeSqrtFrom;
            break;
    }
    glUniform1ui(glGetUniformLocation(program, "u_mode"), mode);
    if (!abc.empty())
        glDispatchCompute(static_cast<GLuint>((abc.size() + shared::kProbeGroupSize - 1) / shared::kProbeGroupSize), 1,
                          1);
    glUseProgram(0);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> out(abc.size());
    if (!out.empty())
        glGetNamedBufferSubData(m.probe_out, 0, static_cast<GLsizeiptr>(out.size() * sizeof(float)), out.data());
    check_gl("probe");
    return out;
}

std::string_view shipped_glsl(std::string_view name) {
    if (name != "shared.h" && name != "patchcull_tcs.h") return {};
    const char* text = find_shader_source(name);
    return text ? std::string_view(text) : std::string_view();
}

// ---- Hi-Z textures ------------------------------------------------------------------------

namespace {

std::vector<HiZLevel> hiz_layout(int width, int height) {
    const int levels = HiZPyramid::level_count(width, height);
    std::vector<HiZLevel> layout(static_cast<std::size_t>(levels));
    std::size_t offset = 0;
    int w = width, h = height;
    for (int l = 0; l < levels; ++l) {
        w = (w + 1) / 2;
        h = (h + 1) / 2;
        layout[static_cast<std::size_t>(l)] = {w, h, offset};
        offset += static_cast<std::size_t>(w) * h;
    }
    return layout;
}

}  // namespace

HiZTexture create_hiz_texture(int width, int height) {
    if (width < 1 || height < 1 || width > 8192 || height > 8192)
        throw Error("GL: create_hiz_texture: size " + std::to_string(width) + "x" + std::to_string(height) +
                    " outside [1, 8192]");
    const std::vector<HiZLevel> layout = hiz_layout(width, height);
    const int levels = static_cast<int>(layout.size());
    const int pot_w = static_cast<int>(std::bit_ceil(static_cast<unsigned>(layout[0].width)));
    const int pot_h = static_cast<int>(std::bit_ceil(static_cast<unsigned>(layout[0].height)));
    HiZTexture hiz{0, width, height};
    glCreateTextures(GL_TEXTURE_2D, 1, &hiz.texture);
    glTextureStorage2D(hiz.texture, levels, GL_R32F, pot_w, pot_h);
    glTextureParameteri(hiz.texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    glTextureParameteri(hiz.texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    // Zero everywhere (Niessner & Loop: unused texels 0), so that nothing undefined is ever stored.
    const float zero = 0.0f;
    for (int l = 0; l < levels; ++l) glClearTexImage(hiz.texture, l, GL_RED, GL_FLOAT, &zero);
    check_gl("create_hiz_texture");
    return hiz;
}

std::vector<float> read_hiz_texture(const HiZTexture& hiz) {
    if (!glIsTexture(hiz.texture))
        throw Error("GL: read_hiz_texture: " + std::to_string(hiz.texture) + " is not a texture");
    const std::vector<HiZLevel> layout = hiz_layout(hiz.width, hiz.height);
    const HiZLevel& last = layout.back();
    std::vector<float> out(last.offset + static_cast<std::size_t>(last.width) * last.height);
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    for (std::size_t l = 0; l < layout.size(); ++l) {
        const HiZLevel& lv = layout[l];
        const std::size_t n = static_cast<std::size_t>(lv.width) * lv.height;
        glGetTextureSubImage(hiz.texture, static_cast<GLint>(l), 0, 0, 0, lv.width, lv.height, 1, GL_RED, GL_FLOAT,
                             static_cast<GLsizei>(n * sizeof(float)), out.data() + lv.offset);
    }
    check_gl("read_hiz_texture");
    return out;
}

// ---- helpers ------------------------------------------------------------------------------

namespace detail {

void check_buffer_size(const char* who, const char* what, GLuint buffer, std::size_t bytes) {
    if (!glIsBuffer(buffer))
        throw Error(std::string("GL: ") + who + ": " + what + " " + std::to_string(buffer) + " is not a buffer");
    GLint64 size = 0;
    glGetNamedBufferParameteri64v(buffer, GL_BUFFER_SIZE, &size);
    if (static_cast<std::uint64_t>(size) < bytes)
        throw Error(std::string("GL: ") + who + ": " + what + " buffer of " + std::to_string(size) + " bytes, " +
                    std::to_string(bytes) + " needed");
}

void check_patch_buffers(const char* who, const PatchBuffers& patches) {
    if (patches.count == 0) return;
    if (patches.first + patches.count > 0xFFFFFFFFu / 16)
        throw Error(std::string("GL: ") + who + ": patch range past 2^28 patches");
    const std::size_t end = patches.first + patches.count;
    check_buffer_size(who, "control-point", patches.control_points, end * 16 * 4 * sizeof(float));
    check_buffer_size(who, "flag", patches.flags, end * sizeof(std::uint32_t));
    if (patches.margins) check_buffer_size(who, "margin", patches.margins, end * sizeof(float));
}

void begin_pass(const char* who) {
    const GLenum e = glGetError();
    if (e == GL_NO_ERROR) return;
    while (glGetError() != GL_NO_ERROR) {
    }
    throw Error("GL: error " + hex(e) + " pending before " + who + " (left by an earlier GL call)");
}

void bind_patch_buffers(const PatchBuffers& patches) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingControlPoints, patches.control_points);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingCullFlags, patches.flags);
    if (patches.margins) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingMaxDisplacement, patches.margins);
}

void finish_pass(const char* who) {
    glUseProgram(0);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                    GL_BUFFER_UPDATE_BARRIER_BIT);
    check_gl(who);
}

void store_planes(const FrustumPlanes& planes, pp::vec4 clip_rows[4], pp::vec4 normal_length[2], pp::vec4& depth) {
    depth = {planes.near_w, planes.far_w, planes.far_limit, 0.0f};
    for (int r = 0; r < 4; ++r) {
        const Vec4 m = planes.clip_rows[r];
        clip_rows[r] = {m.x, m.y, m.z, m.w};
    }
    float nl[8] = {};
    for (int q = 0; q < 6; ++q) nl[q] = planes.normal_length[q];
    normal_length[0] = {nl[0], nl[1], nl[2], nl[3]};
    normal_length[1] = {nl[4], nl[5], nl[6], nl[7]};
}

ParamBlock::ParamBlock() = default;
ParamBlock::~ParamBlock() { glDeleteBuffers(1, &buffer_); }
void ParamBlock::create(std::size_t size) {
    glCreateBuffers(1, &buffer_);
    glNamedBufferStorage(buffer_, static_cast<GLsizeiptr>(size), nullptr, GL_DYNAMIC_STORAGE_BIT);
}

}  // namespace detail
}  // namespace patchcull::gl
