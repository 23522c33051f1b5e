// FrustumDispPass (patchcull/gl/gl_passes.h): cull_frustum_disp_scalar (Sathe's displaced AABB) on the
// GPU, shaders/frustum_disp.comp.glsl (over a GpuPatchSource with patch_source_defines).
#include "pass_common.h"

namespace patchcull::gl {

// The std140 block of pass_params.h: four vec4 rows, then four uints.
static_assert(sizeof(pp::FrustumDispParams) == 5 * 16 + 16);
static_assert(offsetof(pp::FrustumDispParams, first_patch) == 5 * 16);

struct FrustumDispPass::Impl : detail::PassState {
    using PassState::PassState;
};

namespace {

pp::FrustumDispParams disp_params(const FrustumPlanes& planes, bool has_margins, bool write_plane_values) {
    pp::FrustumDispParams params;
    for (int r = 0; r < 4; ++r) {
        const Vec4 m = planes.clip_rows[r];
        params.clip_rows[r] = {m.x, m.y, m.z, m.w};
    }
    params.plane_depth = {planes.near_w, planes.far_w, planes.far_limit, 0.0f};
    params.has_margins = has_margins ? 1u : 0u;
    params.write_plane_values = write_plane_values ? 1u : 0u;
    return params;
}

}  // namespace

FrustumDispPass::FrustumDispPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
FrustumDispPass::FrustumDispPass(FrustumDispPass&&) noexcept = default;
FrustumDispPass& FrustumDispPass::operator=(FrustumDispPass&&) noexcept = default;
FrustumDispPass::~FrustumDispPass() = default;

void FrustumDispPass::run(const PatchBuffers& patches, const Mat4& object_to_clip, ClipDepth depth,
                          std::uint32_t plane_values) {
    detail::begin_pass("FrustumDispPass");
    detail::check_patch_buffers("FrustumDispPass", patches);
    if (plane_values)
        detail::check_buffer_size("FrustumDispPass", "plane-value", plane_values,
                                  (patches.first + patches.count) * 6 * sizeof(float));
    // The CPU kernel's planes (frustum.cpp): the same matrix, so the same corners.
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, depth);  // refuses a contradiction
    if (patches.count == 0) return;
    pp::FrustumDispParams params = disp_params(planes, patches.margins != 0, plane_values != 0);
    glUseProgram(impl_->context.program("frustum_disp.comp.glsl"));
    detail::bind_patch_buffers(patches);
    if (plane_values) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingPlaneValues, plane_values);
    detail::dispatch_patches(impl_->block, params, patches.first, patches.count, shared::kCullGroupSize);
    detail::finish_pass("FrustumDispPass");
}

void FrustumDispPass::run(const PatchBuffers& patches, const CullView& view, std::uint32_t plane_values) {
    run(patches, view.object_to_clip, view.depth, plane_values);
}

void FrustumDispPass::run(const GpuPatchSource& source, const Mat4& object_to_clip, ClipDepth depth,
                          std::uint32_t plane_values) {
    detail::begin_pass("FrustumDispPass");
    const pp::PatchSourceParams source_params = detail::check_patch_source("FrustumDispPass", impl_->context, source);
    if (plane_values)
        detail::check_buffer_size("FrustumDispPass", "plane-value", plane_values,
                                  (source.first + source.count) * 6 * sizeof(float));
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, depth);  // refuses a contradiction
    if (source.count == 0) return;
    pp::FrustumDispParams params = disp_params(planes, source.margins != 0, plane_values != 0);
    glUseProgram(impl_->context.program("frustum_disp.comp.glsl", detail::patch_source_defines(source)));
    detail::bind_patch_source(*impl_, source, source_params);
    if (plane_values) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingPlaneValues, plane_values);
    detail::dispatch_patches(impl_->block, params, source.first, source.count, shared::kCullGroupSize);
    detail::finish_pass("FrustumDispPass");
}

void FrustumDispPass::run(const GpuPatchSource& source, const CullView& view, std::uint32_t plane_values) {
    run(source, view.object_to_clip, view.depth, plane_values);
}

}  // namespace patchcull::gl
