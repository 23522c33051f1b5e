// BackpatchCuller (patchcull/gl_backpatch.h): the GPU back-patch cull passes tcone, ncone and ptp.
// Self-contained (its own programs and buffers; shares only the buffer layouts and bindings of
// shaders/shared.h with the renderer). GL 4.5 direct state access.
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "backpatch_shared.h"
#include "patchcull/error.h"
#include "patchcull/gl_backpatch.h"
#include "renderer_internal.h"
#include "shader_sources.h"
#include "shared.h"

namespace patchcull::gl {

namespace {

namespace bs = backpatch_shared;

static_assert(kFlagBackPatch == sh::kCullBackPatch);

// Shader compilation, GL error checks and buffer uploads are the renderer's (renderer_internal.h).
using detail::check_gl;
using detail::upload;

GLuint compute_program(const char* name, const std::string& defines) {
    return detail::link_program({{name, GL_COMPUTE_SHADER}}, name, defines);
}

// Rows x, y, w of s * object_to_clip, s = ptp_orientation_sign (backpatch.h), as the CPU kernels'
// ptp_clip_rows (tests/gl/backpatch_gpu_test.cpp compares the two). False: nothing may be culled.
bool ptp_rows(const Mat4& object_to_clip, float alpha, float rows[3][4]) {
    const int sign = ptp_orientation_sign(object_to_clip, alpha);
    if (sign == 0) return false;
    const float s = static_cast<float>(sign);
    const int src_row[3] = {0, 1, 3};  // x, y, w
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) rows[r][c] = s * object_to_clip.at(src_row[r], c);
    return true;
}

// Patches per dispatch: at most 65535 work groups (the GL minimum of the x count).
constexpr std::size_t kMaxGroups = 65535;

}  // namespace

const char* backpatch_method_name(BackpatchMethod method) {
    switch (method) {
        case BackpatchMethod::tcone: return "tcone";
        case BackpatchMethod::ncone: return "ncone";
        case BackpatchMethod::ptp: return "ptp";
    }
    return "?";
}

struct BackpatchCuller::Impl {
    GLuint tcone = 0, ncone = 0, ptp = 0, probe = 0;
    GLuint own_points = 0, flags = 0, planes = 0, probe_in = 0, probe_out = 0, cone_values = 0;
    GLuint points = 0;  // own_points or the caller's buffer
    std::size_t count = 0;
    bool fma_via_double = false;

    ~Impl() {
        for (GLuint p : {tcone, ncone, ptp, probe}) glDeleteProgram(p);
        const GLuint buffers[] = {own_points, flags, planes, probe_in, probe_out, cone_values};
        glDeleteBuffers(6, buffers);
    }

    // Programs are compiled on first use (llvmpipe takes seconds for ncone); link() drops them
    // all (after the fma mode changed).
    void link() {
        for (GLuint* p : {&tcone, &ncone, &ptp, &probe}) {
            glDeleteProgram(*p);
            *p = 0;
        }
    }

    GLuint program(GLuint& slot, const char* name) {
        if (!slot) slot = compute_program(name, fma_via_double ? "#define PATCHCULL_FMA_VIA_DOUBLE 1\n" : "");
        return slot;
    }
    GLuint tcone_program() { return program(tcone, "cull_tcone.comp.glsl"); }
    GLuint ncone_program() { return program(ncone, "cull_ncone.comp.glsl"); }
    GLuint ptp_program() { return program(ptp, "cull_ptp.comp.glsl"); }
    GLuint probe_program() { return program(probe, "backpatch_probe.comp.glsl"); }

    void resize_flags(std::size_t n) {
        count = n;
        upload(flags, n * sizeof(std::uint32_t), nullptr);
        glClearNamedBufferData(flags, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    }

    void read_flags(std::vector<std::uint8_t>& out) const {
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        std::vector<std::uint32_t> words(count);
        if (count)
            glGetNamedBufferSubData(flags, 0, static_cast<GLsizeiptr>(count * sizeof(std::uint32_t)), words.data());
        out.resize(count);
        for (std::size_t p = 0; p < count; ++p) out[p] = words[p] != 0 ? 1 : 0;
        check_gl("back-patch flag read-back");
    }

    void cull_cone(GLuint program, Vec3 eye, std::vector<std::uint8_t>* culled, std::vector<float>* cones) {
        if (cones) upload(cone_values, count * bs::kConeValues * sizeof(float), nullptr);
        glUseProgram(program);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingControlPoints, points);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingBackPatchFlags, flags);
        glUniform1ui(glGetUniformLocation(program, "u_patch_count"), static_cast<GLuint>(count));
        glUniform3f(glGetUniformLocation(program, "u_eye"), eye.x, eye.y, eye.z);
        glUniform1f(glGetUniformLocation(program, "u_zero"), 0.0f);
        glUniform1i(glGetUniformLocation(program, "u_write_cones"), cones ? 1 : 0);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, bs::kBindingConeValues, cone_values);
        const GLint first_loc = glGetUniformLocation(program, "u_first_patch");
        const std::size_t per_dispatch = kMaxGroups * bs::kConeGroupSize;
        for (std::size_t first = 0; first < count; first += per_dispatch) {
            const std::size_t n = std::min(per_dispatch, count - first);
            glUniform1ui(first_loc, static_cast<GLuint>(first));
            glDispatchCompute(static_cast<GLuint>((n + bs::kConeGroupSize - 1) / bs::kConeGroupSize), 1, 1);
        }
        glUseProgram(0);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        check_gl("back-patch cone pass");
        if (culled) read_flags(*culled);
        if (cones) {
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            cones->assign(count * bs::kConeValues, 0.0f);
            if (count)
                glGetNamedBufferSubData(cone_values, 0, static_cast<GLsizeiptr>(cones->size() * sizeof(float)),
                                        cones->data());
            check_gl("back-patch cone values read-back");
        }
    }
};

BackpatchCuller::BackpatchCuller(const GlContext& ctx) : impl_(std::make_unique<Impl>()) {
    ctx.make_current();
    if (epoxy_gl_version() < 45)
        throw Error("GL: BackpatchCuller needs OpenGL 4.5 (context has " + ctx.version() + ")");
    Impl& m = *impl_;
    m.fma_via_double = ctx.is_software();
    m.link();
    GLuint buffers[6];
    glCreateBuffers(6, buffers);
    m.own_points = buffers[0];
    m.flags = buffers[1];
    m.planes = buffers[2];
    m.probe_in = buffers[3];
    m.probe_out = buffers[4];
    m.cone_values = buffers[5];
    upload(m.cone_values, 0, nullptr);
    m.points = m.own_points;
    upload(m.own_points, 0, nullptr);
    upload(m.planes, 0, nullptr);
    m.resize_flags(0);
    check_gl("BackpatchCuller setup");
    if (!m.fma_via_double) {
        // GLSL fma() on a GPU: cases where a*b + c lies just off a midpoint between two floats, so
        // any second rounding gives the other neighbour (as PatchRenderer's check).
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
            m.fma_via_double = true;
            m.link();
        }
    }
}

BackpatchCuller::BackpatchCuller(BackpatchCuller&&) noexcept = default;
BackpatchCuller& BackpatchCuller::operator=(BackpatchCuller&&) noexcept = default;
BackpatchCuller::~BackpatchCuller() = default;

void BackpatchCuller::set_patches(const std::vector<BezierPatch>& patches) {
    static_assert(sizeof(BezierPatch) == kPatchPoints * 4 * sizeof(float), "BezierPatch must be 16 packed float4");
    Impl& m = *impl_;
    upload(m.own_points, patches.size() * sizeof(BezierPatch), patches.empty() ? nullptr : &patches[0].cp[0].x);
    m.points = m.own_points;
    m.resize_flags(patches.size());
    check_gl("BackpatchCuller::set_patches");
}

void BackpatchCuller::set_patches(const PatchBatchView& patches) {
    Impl& m = *impl_;
    detail::upload_patch_batch(m.own_points, patches);
    m.points = m.own_points;
    m.resize_flags(patches.count);
    check_gl("BackpatchCuller::set_patches");
}

void BackpatchCuller::use_patch_buffer(std::uint32_t buffer, std::size_t count) {
    Impl& m = *impl_;
    detail::check_patch_buffer("use_patch_buffer", buffer, count);
    m.points = buffer;
    m.resize_flags(count);
    check_gl("BackpatchCuller::use_patch_buffer");
}

std::size_t BackpatchCuller::patch_count() const { return impl_->count; }
std::uint32_t BackpatchCuller::patch_buffer() const { return impl_->points; }

void BackpatchCuller::cull_tcone(Vec3 eye, std::vector<std::uint8_t>* culled, std::vector<float>* cones) {
    impl_->cull_cone(impl_->tcone_program(), eye, culled, cones);
}
void BackpatchCuller::cull_ncone(Vec3 eye, std::vector<std::uint8_t>* culled, std::vector<float>* cones) {
    impl_->cull_cone(impl_->ncone_program(), eye, culled, cones);
}

void BackpatchCuller::cull_ptp(const Mat4& object_to_clip, float alpha, PtpRule rule, std::vector<std::uint8_t>* culled,
                               std::vector<float>* planes, std::vector<float>* margins) {
    Impl& m = *impl_;
    float rows[3][4];
    if (!ptp_rows(object_to_clip, alpha, rows)) {
        glClearNamedBufferData(m.flags, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
        check_gl("back-patch ptp pass (nothing culled)");
        if (culled) m.read_flags(*culled);
        if (planes) planes->clear();
        if (margins) margins->clear();
        return;
    }
    const GLuint program = m.ptp_program();
    const bool diagnostics = planes || margins;
    if (diagnostics) upload(m.planes, m.count * 128 * sizeof(float), nullptr);
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingControlPoints, m.points);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingBackPatchFlags, m.flags);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, bs::kBindingPtpPlanes, m.planes);
    glUniform4fv(glGetUniformLocation(program, "u_rows"), 3, &rows[0][0]);
    glUniform1ui(glGetUniformLocation(program, "u_patch_count"), static_cast<GLuint>(m.count));
    glUniform1i(glGetUniformLocation(program, "u_pcnt"), rule == PtpRule::pcnt ? 1 : 0);
    glUniform1i(glGetUniformLocation(program, "u_write_planes"), diagnostics ? 1 : 0);
    glUniform1f(glGetUniformLocation(program, "u_zero"), 0.0f);
    const GLint first_loc = glGetUniformLocation(program, "u_first_patch");
    const std::size_t per_dispatch = kMaxGroups * bs::kPtpPatchesPerGroup;
    for (std::size_t first = 0; first < m.count; first += per_dispatch) {
        const std::size_t n = std::min(per_dispatch, m.count - first);
        glUniform1ui(first_loc, static_cast<GLuint>(first));
        glDispatchCompute(static_cast<GLuint>((n + bs::kPtpPatchesPerGroup - 1) / bs::kPtpPatchesPerGroup), 1, 1);
    }
    glUseProgram(0);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    check_gl("back-patch ptp pass");
    if (culled) m.read_flags(*culled);
    if (diagnostics) {
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        std::vector<float> both(m.count * 128, 0.0f);
        if (m.count)
            glGetNamedBufferSubData(m.planes, 0, static_cast<GLsizeiptr>(both.size() * sizeof(float)), both.data());
        check_gl("back-patch ptp planes read-back");
        // Per patch: t[64] then thr[64].
        for (std::vector<float>* out : {planes, margins}) {
            if (!out) continue;
            const std::size_t offset = out == planes ? 0 : 64;
            out->resize(m.count * 64);
            for (std::size_t p = 0; p < m.count; ++p)
                std::copy_n(both.begin() + static_cast<std::ptrdiff_t>(128 * p + offset), 64,
                            out->begin() + static_cast<std::ptrdiff_t>(64 * p));
        }
    }
}

void BackpatchCuller::cull(BackpatchMethod method, const Mat4& object_to_clip, Vec3 eye, float alpha, PtpRule rule,
                           std::vector<std::uint8_t>* culled) {
    switch (method) {
        case BackpatchMethod::tcone: cull_tcone(eye, culled); return;
        case BackpatchMethod::ncone: cull_ncone(eye, culled); return;
        case BackpatchMethod::ptp: cull_ptp(object_to_clip, alpha, rule, culled); return;
    }
}

std::uint32_t BackpatchCuller::flag_buffer() const { return impl_->flags; }

std::vector<std::uint32_t> BackpatchCuller::read_flag_words() const {
    const Impl& m = *impl_;
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<std::uint32_t> words(m.count);
    if (m.count)
        glGetNamedBufferSubData(m.flags, 0, static_cast<GLsizeiptr>(m.count * sizeof(std::uint32_t)), words.data());
    check_gl("back-patch flag read-back");
    return words;
}

bool BackpatchCuller::fma_via_double() const { return impl_->fma_via_double; }

std::vector<float> BackpatchCuller::probe(BackpatchProbe op, const std::vector<Vec3>& abc) {
    Impl& m = *impl_;
    std::vector<float> in(abc.size() * 4);
    for (std::size_t i = 0; i < abc.size(); ++i) {
        in[4 * i] = abc[i].x;
        in[4 * i + 1] = abc[i].y;
        in[4 * i + 2] = abc[i].z;
        in[4 * i + 3] = 0.0f;
    }
    upload(m.probe_in, in.size() * sizeof(float), in.data());
    upload(m.probe_out, abc.size() * sizeof(float), nullptr);
    const GLuint program = m.probe_program();
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, bs::kBindingProbeIn, m.probe_in);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, bs::kBindingProbeOut, m.probe_out);
    glUniform1ui(glGetUniformLocation(program, "u_count"), static_cast<GLuint>(abc.size()));
    GLuint mode = bs::kProbeFma;
    switch (op) {
        case BackpatchProbe::fma: mode = bs::kProbeFma; break;
        case BackpatchProbe::div: mode = bs::kProbeDiv; break;
        case BackpatchProbe::sqrt: mode = bs::kProbeSqrt; break;
        case BackpatchProbe::div_from: mode = bs::kProbeDivFrom; break;
        case BackpatchProbe::sqrt_from: mode = bs::kProbeSqrtFrom; break;
    }
    glUniform1ui(glGetUniformLocation(program, "u_mode"), mode);
    if (!abc.empty()) {
        if (abc.size() > kMaxGroups * bs::kProbeGroupSize) throw Error("GL: probe: too many inputs");
        glDispatchCompute(static_cast<GLuint>((abc.size() + bs::kProbeGroupSize - 1) / bs::kProbeGroupSize), 1, 1);
    }
    glUseProgram(0);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> out(abc.size());
    if (!out.empty())
        glGetNamedBufferSubData(m.probe_out, 0, static_cast<GLsizeiptr>(out.size() * sizeof(float)), out.data());
    check_gl("back-patch probe");
    return out;
}

}  // namespace patchcull::gl
