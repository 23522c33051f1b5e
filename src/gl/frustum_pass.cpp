// FrustumPass (patchcull/gl/gl_passes.h): cull_frustum_scalar on the GPU, shaders/frustum.comp.glsl.
#include "pass_common.h"

namespace patchcull::gl {

struct FrustumPass::Impl : detail::PassState {
    using PassState::PassState;
};

FrustumPass::FrustumPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
FrustumPass::FrustumPass(FrustumPass&&) noexcept = default;
FrustumPass& FrustumPass::operator=(FrustumPass&&) noexcept = default;
FrustumPass::~FrustumPass() = default;

void FrustumPass::run(const PatchBuffers& patches, const FrustumPlanes& planes, std::uint32_t plane_values) {
    detail::begin_pass("FrustumPass");
    detail::check_patch_buffers("FrustumPass", patches);
    if (plane_values)
        detail::check_buffer_size("FrustumPass", "plane-value", plane_values,
                                  (patches.first + patches.count) * 6 * sizeof(float));
    if (patches.count == 0) return;
    pp::FrustumParams params;
    detail::store_planes(planes, params.clip_rows, params.plane_normal_length, params.plane_depth);
    params.has_margins = patches.margins ? 1u : 0u;
    params.write_plane_values = plane_values ? 1u : 0u;
    glUseProgram(impl_->context.program("frustum.comp.glsl", detail::margins_define(patches.margins != 0)));
    detail::bind_patch_buffers(patches);
    if (plane_values) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingPlaneValues, plane_values);
    detail::dispatch_patches(impl_->block, params, patches.first, patches.count, shared::kCullGroupSize);
    detail::finish_pass("FrustumPass");
}

void FrustumPass::run(const PatchBuffers& patches, const CullView& view, std::uint32_t plane_values) {
    run(patches, view.planes, plane_values);
}

void FrustumPass::run(const GpuPatchSource& source, const FrustumPlanes& planes, std::uint32_t plane_values) {
    detail::begin_pass("FrustumPass");
    const pp::PatchSourceParams source_params = detail::check_patch_source("FrustumPass", impl_->context, source);
    if (plane_values)
        detail::check_buffer_size("FrustumPass", "plane-value", plane_values,
                                  (source.first + source.count) * 6 * sizeof(float));
    if (source.count == 0) return;
    pp::FrustumParams params;
    detail::store_planes(planes, params.clip_rows, params.plane_normal_length, params.plane_depth);
    params.has_margins = source.margins ? 1u : 0u;
    params.write_plane_values = plane_values ? 1u : 0u;
    glUseProgram(impl_->context.program("frustum.comp.glsl", std::string(detail::patch_source_defines(source)) +
                                                                 detail::margins_define(source.margins != 0)));
    detail::bind_patch_source(*impl_, source, source_params);
    if (plane_values) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingPlaneValues, plane_values);
    detail::dispatch_patches(impl_->block, params, source.first, source.count, shared::kCullGroupSize);
    detail::finish_pass("FrustumPass");
}

void FrustumPass::run(const GpuPatchSource& source, const CullView& view, std::uint32_t plane_values) {
    run(source, view.planes, plane_values);
}

}  // namespace patchcull::gl
