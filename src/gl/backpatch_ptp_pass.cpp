// BackpatchPtpPass (patchcull/gl/gl_passes.h): cull_ptp_scalar on the GPU with Loop, Niessner & Eisenacher §6's 16
// invocations per patch, shaders/backpatch_ptp.comp.glsl.
#include "pass_common.h"

namespace patchcull::gl {

namespace {

// Rows x, y, w of s * object_to_clip, s = ptp_orientation_sign (backpatch.h), as the CPU kernels'
// ptp_clip_rows (tests/gl/backpatch_gpu_test.cpp compares the two). False: nothing may be culled.
bool ptp_rows(const Mat4& object_to_clip, float alpha, pp::vec4 rows[3]) {
    const int sign = ptp_orientation_sign(object_to_clip, alpha);
    if (sign == 0) return false;
    const float s = static_cast<float>(sign);
    const int src_row[3] = {0, 1, 3};  // x, y, w
    for (int r = 0; r < 3; ++r)
        rows[r] = {s * object_to_clip.at(src_row[r], 0), s * object_to_clip.at(src_row[r], 1),
                   s * object_to_clip.at(src_row[r], 2), s * object_to_clip.at(src_row[r], 3)};
    return true;
}

}  // namespace

struct BackpatchPtpPass::Impl : detail::PassState {
    using PassState::PassState;
};

BackpatchPtpPass::BackpatchPtpPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
BackpatchPtpPass::BackpatchPtpPass(BackpatchPtpPass&&) noexcept = default;
BackpatchPtpPass& BackpatchPtpPass::operator=(BackpatchPtpPass&&) noexcept = default;
BackpatchPtpPass::~BackpatchPtpPass() = default;

bool BackpatchPtpPass::run(const PatchBuffers& patches, const Mat4& object_to_clip, float alpha, PtpRule rule,
                           std::uint32_t plane_values) {
    detail::begin_pass("BackpatchPtpPass");
    detail::check_patch_buffers("BackpatchPtpPass", patches);
    if (plane_values)
        detail::check_buffer_size("BackpatchPtpPass", "plane-value", plane_values,
                                  (patches.first + patches.count) * 128 * sizeof(float));
    pp::BackpatchPtpParams params;
    if (!ptp_rows(object_to_clip, alpha, params.rows)) return false;
    if (patches.count == 0) return true;
    params.has_margins = patches.margins ? 1u : 0u;
    params.pcnt = rule == PtpRule::pcnt ? 1u : 0u;
    params.write_planes = plane_values ? 1u : 0u;
    params.zero = 0.0f;
    glUseProgram(impl_->context.program("backpatch_ptp.comp.glsl"));
    detail::bind_patch_buffers(patches);
    if (plane_values) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingPtpPlanes, plane_values);
    detail::dispatch_patches(impl_->block, params, patches.first, patches.count, shared::kPtpPatchesPerGroup);
    detail::finish_pass("BackpatchPtpPass");
    return true;
}

bool BackpatchPtpPass::run(const GpuPatchSource& source, const Mat4& object_to_clip, float alpha, PtpRule rule,
                           std::uint32_t plane_values) {
    detail::begin_pass("BackpatchPtpPass");
    const pp::PatchSourceParams source_params = detail::check_patch_source("BackpatchPtpPass", impl_->context, source);
    if (plane_values)
        detail::check_buffer_size("BackpatchPtpPass", "plane-value", plane_values,
                                  (source.first + source.count) * 128 * sizeof(float));
    if (source.basis == PatchBasis::gregory) return false;  // never back-patch culled
    pp::BackpatchPtpParams params;
    if (!ptp_rows(object_to_clip, alpha, params.rows)) return false;
    if (source.count == 0) return true;
    params.has_margins = source.margins ? 1u : 0u;
    params.pcnt = rule == PtpRule::pcnt ? 1u : 0u;
    params.write_planes = plane_values ? 1u : 0u;
    params.zero = 0.0f;
    glUseProgram(impl_->context.program("backpatch_ptp.comp.glsl", detail::patch_source_defines(source)));
    detail::bind_patch_source(*impl_, source, source_params);
    if (plane_values) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingPtpPlanes, plane_values);
    detail::dispatch_patches(impl_->block, params, source.first, source.count, shared::kPtpPatchesPerGroup);
    detail::finish_pass("BackpatchPtpPass");
    return true;
}

}  // namespace patchcull::gl
