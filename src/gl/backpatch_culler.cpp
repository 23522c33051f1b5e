// BackpatchCuller (patchcull/gl/gl_backpatch.h): the back-patch passes of gl_passes.h
// (BackpatchConePass, BackpatchPtpPass) over buffers the culler owns, with read-backs.
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_backpatch.h"
#include "patchcull/gl/gl_backpatch_passes.h"
#include "patchcull/gl/gl_passes.h"
#include "renderer_internal.h"
#include "shader_sources.h"
#include "shared.h"

namespace patchcull::gl {

namespace {

std::vector<float> read_floats(GLuint buffer, std::size_t n) {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> out(n, 0.0f);
    if (n) glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(n * sizeof(float)), out.data());
    check_gl("back-patch diagnostics read-back");
    return out;
}

}  // namespace

struct BackpatchCuller::Impl {
    PassContext passes;
    BackpatchConePass cones{passes};
    BackpatchPtpPass ptp{passes};
    std::map<BackpatchMethod, std::unique_ptr<BackpatchPass>> registered;  // other methods' passes
    GLuint own_points = 0, flags = 0, diagnostics = 0;
    GLuint points = 0;  // own_points or the caller's buffer
    std::size_t count = 0;

    ~Impl() {
        const GLuint buffers[] = {own_points, flags, diagnostics};
        glDeleteBuffers(3, buffers);
    }

    PatchBuffers buffers() const { return {points, flags, 0, 0, count}; }

    void resize_flags(std::size_t n) {
        count = n;
        upload(flags, n * sizeof(std::uint32_t), nullptr);
        clear_flags();
    }
    void clear_flags() { glClearNamedBufferData(flags, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr); }

    void read_flags(std::vector<std::uint8_t>& out) const {
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        std::vector<std::uint32_t> words(count);
        if (count)
            glGetNamedBufferSubData(flags, 0, static_cast<GLsizeiptr>(count * sizeof(std::uint32_t)), words.data());
        out.resize(count);
        for (std::size_t p = 0; p < count; ++p) out[p] = words[p] != 0 ? 1 : 0;
        check_gl("back-patch flag read-back");
    }

    void cull_cone(BackpatchMethod method, Vec3 eye, std::vector<std::uint8_t>* culled, std::vector<float>* cones_out) {
        clear_flags();
        if (cones_out) upload(diagnostics, count * shared::kConeValues * sizeof(float), nullptr);
        cones.run(buffers(), method, eye, cones_out ? diagnostics : 0);
        if (culled) read_flags(*culled);
        if (cones_out) *cones_out = read_floats(diagnostics, count * shared::kConeValues);
    }
};

BackpatchCuller::BackpatchCuller(const GlContext& ctx) : impl_((ctx.make_current(), std::make_unique<Impl>())) {
    Impl& m = *impl_;
    GLuint buffers[3];
    glCreateBuffers(3, buffers);
    m.own_points = buffers[0];
    m.flags = buffers[1];
    m.diagnostics = buffers[2];
    upload(m.own_points, 0, nullptr);
    upload(m.diagnostics, 0, nullptr);
    m.points = m.own_points;
    m.resize_flags(0);
    check_gl("BackpatchCuller setup");
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
    impl_->cull_cone(BackpatchMethod::tcone, eye, culled, cones);
}
void BackpatchCuller::cull_ncone(Vec3 eye, std::vector<std::uint8_t>* culled, std::vector<float>* cones) {
    impl_->cull_cone(BackpatchMethod::ncone, eye, culled, cones);
}

void BackpatchCuller::cull_ptp(const Mat4& object_to_clip, float alpha, PtpRule rule, std::vector<std::uint8_t>* culled,
                               std::vector<float>* planes, std::vector<float>* margins) {
    Impl& m = *impl_;
    m.clear_flags();
    const bool diagnostics = planes || margins;
    if (diagnostics) upload(m.diagnostics, m.count * 128 * sizeof(float), nullptr);
    const bool ran = m.ptp.run(m.buffers(), object_to_clip, alpha, rule, diagnostics ? m.diagnostics : 0);
    if (culled) m.read_flags(*culled);
    if (!ran) {
        if (planes) planes->clear();
        if (margins) margins->clear();
        return;
    }
    if (diagnostics) {
        const std::vector<float> both = read_floats(m.diagnostics, m.count * 128);
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
    CullView view;
    view.object_to_clip = object_to_clip;
    view.eye = eye;
    view.has_eye = true;
    view.alpha = alpha;
    view.orientation = ptp_orientation_sign(object_to_clip, alpha);
    cull(method, view, BackpatchOptions{rule}, culled);
}

void BackpatchCuller::cull(BackpatchMethod method, const CullView& view, const BackpatchOptions& options,
                           std::vector<std::uint8_t>* culled) {
    Impl& m = *impl_;
    std::unique_ptr<BackpatchPass>& pass = m.registered[method];
    if (!pass) pass = make_backpatch_pass(m.passes, method);
    m.clear_flags();
    pass->run(m.buffers(), view, options);
    if (culled) m.read_flags(*culled);
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

bool BackpatchCuller::fma_via_double() const { return impl_->passes.fma_via_double(); }

std::vector<float> BackpatchCuller::probe(BackpatchProbe op, const std::vector<Vec3>& abc) {
    return impl_->passes.probe(op, abc);
}

}  // namespace patchcull::gl
