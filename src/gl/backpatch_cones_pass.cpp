// BackpatchConePass (patchcull/gl/gl_passes.h): cull_tcone_scalar and cull_ncone_scalar on the GPU,
// shaders/backpatch_cones.comp.glsl (ncone compiled with PATCHCULL_NCONE).
#include "pass_common.h"

namespace patchcull::gl {

struct BackpatchConePass::Impl : detail::PassState {
    using PassState::PassState;
};

BackpatchConePass::BackpatchConePass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
BackpatchConePass::BackpatchConePass(BackpatchConePass&&) noexcept = default;
BackpatchConePass& BackpatchConePass::operator=(BackpatchConePass&&) noexcept = default;
BackpatchConePass::~BackpatchConePass() = default;

void BackpatchConePass::run(const PatchBuffers& patches, BackpatchMethod method, Vec3 eye, std::uint32_t cone_values) {
    if (method != BackpatchMethod::tcone && method != BackpatchMethod::ncone)
        throw Error(std::string("GL: BackpatchConePass runs tcone and ncone, not ") + backpatch_method_name(method));
    detail::begin_pass("BackpatchConePass");
    detail::check_patch_buffers("BackpatchConePass", patches);
    if (cone_values)
        detail::check_buffer_size("BackpatchConePass", "cone-value", cone_values,
                                  (patches.first + patches.count) * shared::kConeValues * sizeof(float));
    if (patches.count == 0) return;
    pp::BackpatchConeParams params;
    params.eye = {eye.x, eye.y, eye.z, 1.0f};
    params.has_margins = patches.margins ? 1u : 0u;
    params.write_cones = cone_values ? 1u : 0u;
    params.zero = 0.0f;
    const bool ncone = method == BackpatchMethod::ncone;
    glUseProgram(impl_->context.program("backpatch_cones.comp.glsl", ncone ? "#define PATCHCULL_NCONE 1\n" : ""));
    detail::bind_patch_buffers(patches);
    if (cone_values) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingConeValues, cone_values);
    detail::dispatch_patches(impl_->block, params, patches.first, patches.count, shared::kConeGroupSize);
    detail::finish_pass("BackpatchConePass");
}

void BackpatchConePass::run(const GpuPatchSource& source, BackpatchMethod method, Vec3 eye, std::uint32_t cone_values) {
    if (method != BackpatchMethod::tcone && method != BackpatchMethod::ncone)
        throw Error(std::string("GL: BackpatchConePass runs tcone and ncone, not ") + backpatch_method_name(method));
    detail::begin_pass("BackpatchConePass");
    const pp::PatchSourceParams source_params = detail::check_patch_source("BackpatchConePass", impl_->context, source);
    if (cone_values)
        detail::check_buffer_size("BackpatchConePass", "cone-value", cone_values,
                                  (source.first + source.count) * shared::kConeValues * sizeof(float));
    if (source.count == 0) return;
    pp::BackpatchConeParams params;
    params.eye = {eye.x, eye.y, eye.z, 1.0f};
    params.has_margins = source.margins ? 1u : 0u;
    params.write_cones = cone_values ? 1u : 0u;
    params.zero = 0.0f;
    // A Gregory source has one cone for both methods (the Gregory program ignores PATCHCULL_NCONE).
    const bool ncone = method == BackpatchMethod::ncone && source.basis != PatchBasis::gregory;
    glUseProgram(impl_->context.program(
        "backpatch_cones.comp.glsl",
        std::string(ncone ? "#define PATCHCULL_NCONE 1\n" : "") + detail::patch_source_defines(source)));
    detail::bind_patch_source(*impl_, source, source_params);
    if (cone_values) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingConeValues, cone_values);
    detail::dispatch_patches(impl_->block, params, source.first, source.count, shared::kConeGroupSize);
    detail::finish_pass("BackpatchConePass");
}

}  // namespace patchcull::gl
