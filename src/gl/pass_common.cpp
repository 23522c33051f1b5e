// PassContext and the helpers of the cull passes (src/gl/pass_common.h, patchcull/gl/gl_passes.h).
#include "pass_common.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

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
static_assert(sizeof(pp::PatchSourceParams) == 48);

// shared.h's patch-source constants are core/patch_source.h's: the basis order, the phantom slots
// of each boundary mask and the change of basis' constants.
static_assert(shared::kSourceBasisBezier == static_cast<unsigned>(PatchBasis::bezier));
static_assert(shared::kSourceBasisBspline == static_cast<unsigned>(PatchBasis::bspline));
static_assert(shared::kSourceBasisGregory == static_cast<unsigned>(PatchBasis::gregory));
static_assert(std::bit_cast<float>(shared::kBsplineSixthBits) == 1.0f / 6.0f);
static_assert(std::bit_cast<float>(shared::kBsplineThirdBits) == 1.0f / 3.0f);
static_assert([] {
    for (unsigned m = 0; m < 16; ++m) {
        unsigned phantom = 0;
        if (m & 1u) phantom |= shared::kBsplinePhantomRow0;
        if (m & 2u) phantom |= shared::kBsplinePhantomColumn3;
        if (m & 4u) phantom |= shared::kBsplinePhantomRow3;
        if (m & 8u) phantom |= shared::kBsplinePhantomColumn0;
        if ((~phantom & 0xFFFFu) != bspline_real_slots(m)) return false;
    }
    return true;
}());

PassContext::Impl::~Impl() {
    for (const auto& [key, program] : programs) glDeleteProgram(program);
    const GLuint buffers[] = {probe_in, probe_out};
    glDeleteBuffers(2, buffers);
}

GLuint PassContext::Impl::program(const char* shader, const std::string& defines) {
    const std::string all = std::string(fma_via_double ? "#define PATCHCULL_FMA_VIA_DOUBLE 1\n" : "") +
                            (native_div_sqrt ? "#define PATCHCULL_NATIVE_DIV_SQRT 1\n" : "") + defines;
    const std::string key = std::string(shader) + "\n" + all;
    auto it = programs.find(key);
    if (it != programs.end()) return it->second;
    const GLuint p = link_program({{shader, GL_COMPUTE_SHADER}}, shader, all);
    programs.emplace(key, p);
    return p;
}

void PassContext::Impl::drop_programs() {
    for (const auto& [key, program] : programs) glDeleteProgram(program);
    programs.clear();
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
            m.drop_programs();
            m.fma_via_double = true;
        }
    }
    if (m.software) {
        // The driver's a / b and sqrt, used as they are when they round correctly here: quotients
        // and roots within half an ulp of a midpoint between two floats (where a 1-ulp
        // approximation or a second rounding often gives the other neighbour), and random ones
        // over wide ranges.
        m.native_div_sqrt = true;
        std::vector<Vec3> div_cases, sqrt_cases;
        std::mt19937 rng(2024);
        std::uniform_int_distribution<std::uint32_t> mantissa(0, (1u << 23) - 1);
        std::uniform_int_distribution<int> exponent(-60, 60);
        auto random_float = [&](int e) { return std::ldexp(1.0f + std::ldexp(float(mantissa(rng)), -23), e); };
        for (int i = 0; i < 2048; ++i) {
            // mid: halfway between m and its upper neighbour (25 bits, exact in double).
            const float m_value = random_float(0), b = random_float(exponent(rng));
            const double mid = static_cast<double>(m_value) + std::ldexp(1.0, -24);
            div_cases.push_back({static_cast<float>(mid * b), b, 0.0f});
            sqrt_cases.push_back({static_cast<float>(mid * mid), 0.0f, 0.0f});
            div_cases.push_back({random_float(exponent(rng)), random_float(exponent(rng)), 0.0f});
            sqrt_cases.push_back({random_float(exponent(rng)), 0.0f, 0.0f});
        }
        const std::vector<float> q = probe(BackpatchProbe::div, div_cases);
        const std::vector<float> r = probe(BackpatchProbe::sqrt, sqrt_cases);
        for (std::size_t i = 0; i < div_cases.size(); ++i)
            m.native_div_sqrt =
                m.native_div_sqrt && q[i] == div_cases[i].x / div_cases[i].y && r[i] == std::sqrt(sqrt_cases[i].x);
        if (!m.native_div_sqrt) m.drop_programs();
    }
}

PassContext::PassContext(PassContext&&) noexcept = default;
PassContext& PassContext::operator=(PassContext&&) noexcept = default;
PassContext::~PassContext() = default;
bool PassContext::fma_via_double() const { return impl_->fma_via_double; }
bool PassContext::native_div_sqrt() const { return impl_->native_div_sqrt; }
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
    if (name != "shared.h" && name != "patchcull_tcs.h" && name != "patchcull_draw_list.h") return {};
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

void check_patch_buffers(const char* who, const PatchBuffers& patches, bool with_points) {
    if (patches.count == 0) return;
    if (patches.first + patches.count > 0xFFFFFFFFu / 16)
        throw Error(std::string("GL: ") + who + ": patch range past 2^28 patches");
    const std::size_t end = patches.first + patches.count;
    if (with_points || patches.control_points)
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

pp::PatchSourceParams check_patch_source(const char* who, PassContext::Impl& context, const GpuPatchSource& source) {
    pp::PatchSourceParams params;
    const GpuPatchSource& s = source;
    if (s.count == 0) return params;  // nothing is read
    const auto fail = [&](const std::string& message) { throw Error(std::string("GL: ") + who + ": " + message); };
    if (s.components != 3 && s.components != 4)
        fail("source.components is " + std::to_string(s.components) +
             "; it must be 3 (x, y, z with w = 1) or 4 (homogeneous w x, w y, w z, w)");
    const std::size_t point_bytes = static_cast<std::size_t>(s.components) * sizeof(float);
    if (s.stride_bytes % 4 != 0 || s.offset_bytes % 4 != 0)
        fail("source.stride_bytes (" + std::to_string(s.stride_bytes) + ") and offset_bytes (" +
             std::to_string(s.offset_bytes) + ") must be multiples of 4: the vertex buffer is read as floats");
    if (s.stride_bytes < s.offset_bytes + point_bytes)
        fail("source.stride_bytes is " + std::to_string(s.stride_bytes) + ", smaller than offset_bytes (" +
             std::to_string(s.offset_bytes) + ") + " + std::to_string(point_bytes) + " bytes of " +
             std::to_string(s.components) + " floats: a point must lie inside its vertex");
    if (s.basis != PatchBasis::bezier && s.basis != PatchBasis::bspline && s.basis != PatchBasis::gregory)
        fail("unknown source.basis " + std::to_string(static_cast<int>(s.basis)));
    const char* basis_name = s.basis == PatchBasis::bezier    ? "bezier"
                             : s.basis == PatchBasis::bspline ? "bspline"
                                                              : "gregory";
    if (s.boundary_masks && s.basis != PatchBasis::bspline)
        fail(std::string("source.boundary_masks is for bspline sources only, and the basis is ") + basis_name);
    if (s.indices_offset_bytes % 4 != 0)
        fail("source.indices_offset_bytes is " + std::to_string(s.indices_offset_bytes) +
             ", not a multiple of 4 (the indices are uints)");
    if (s.point_count == 0) fail("source.point_count is 0 for " + std::to_string(s.count) + " patches");
    const std::size_t n = static_cast<std::size_t>(patch_source_points(s.basis));
    const std::size_t end = s.source_first + s.count;  // source patches [source_first, end) are read
    if (end > 0xFFFFFFFFu / 32) fail("source patch range past 2^27 patches");
    if (!s.indices && end > s.point_count / n)
        fail("source.indices is 0, so patch s reads points " + std::to_string(n) + " s .. " + std::to_string(n) +
             " s + " + std::to_string(n - 1) + ": source patches up to " + std::to_string(end) + " need " +
             std::to_string(end * n) + " points, but point_count is " + std::to_string(s.point_count));
    // The storage blocks' sizes: the driver's limit, and 32-bit indices in the shader.
    if (context.max_storage_block < 0) glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &context.max_storage_block);
    const std::size_t limit = std::min<std::size_t>(
        context.max_storage_block > 0 ? static_cast<std::size_t>(context.max_storage_block) : 0xFFFFFFFFu, 0xFFFFFFFFu);
    const auto check_block = [&](const char* what, GLuint buffer, std::size_t bytes) {
        if (bytes > limit)
            fail(std::string(what) + " reads end at byte " + std::to_string(bytes) +
                 ", past GL_MAX_SHADER_STORAGE_BLOCK_SIZE (" + std::to_string(limit) + ")");
        check_buffer_size(who, what, buffer, bytes);
    };
    if (s.point_count > limit || s.stride_bytes > limit)
        fail("source.point_count (" + std::to_string(s.point_count) + ") or stride_bytes (" +
             std::to_string(s.stride_bytes) + ") past GL_MAX_SHADER_STORAGE_BLOCK_SIZE (" + std::to_string(limit) +
             ")");
    check_block("vertex", s.vertices, s.offset_bytes + (s.point_count - 1) * s.stride_bytes + point_bytes);
    if (s.indices) check_block("index", s.indices, s.indices_offset_bytes + end * n * sizeof(std::uint32_t));
    if (s.boundary_masks) check_block("boundary-mask", s.boundary_masks, (s.masks_offset_bytes + end + 3) / 4 * 4);
    check_patch_buffers(who, s.flag_buffers(), false);
    params.vertex_base = static_cast<pp::uint>(s.offset_bytes / 4);
    params.vertex_stride = static_cast<pp::uint>(s.stride_bytes / 4);
    params.components = static_cast<pp::uint>(s.components);
    params.point_count = static_cast<pp::uint>(s.point_count);
    params.basis = static_cast<pp::uint>(s.basis);
    params.has_indices = s.indices ? 1u : 0u;
    params.index_base = static_cast<pp::uint>(s.indices_offset_bytes / 4);
    params.has_masks = s.boundary_masks ? 1u : 0u;
    params.mask_base = static_cast<pp::uint>(s.masks_offset_bytes);
    params.patch_delta = static_cast<pp::uint>(s.source_first - s.first);  // mod 2^32
    return params;
}

const char* patch_source_defines(const GpuPatchSource& source) {
    return source.basis == PatchBasis::gregory ? "#define PC_PATCH_SOURCE 1\n#define PC_PATCH_SOURCE_GREGORY 1\n"
                                               : "#define PC_PATCH_SOURCE 1\n";
}

void bind_patch_source(PassState& state, const GpuPatchSource& source, const pp::PatchSourceParams& params) {
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    bind_patch_buffers(source.flag_buffers());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingSourceVertices, source.vertices);
    if (source.indices) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingSourceIndices, source.indices);
    if (source.boundary_masks)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingSourceMasks, source.boundary_masks);
    state.source_block.upload(params, shared::kUniformPatchSource);
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
