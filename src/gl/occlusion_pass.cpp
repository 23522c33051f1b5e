// OcclusionPass (patchcull/gl/gl_passes.h): cull_occlusion_scalar on the GPU against a Hi-Z
// pyramid, shaders/occlusion.comp.glsl.
#include "pass_common.h"

namespace patchcull::gl {

struct OcclusionPass::Impl : detail::PassState {
    using PassState::PassState;
};

namespace {

void check_hiz(const HiZTexture& hiz, ClipDepth depth) {
    if (!glIsTexture(hiz.texture) || hiz.width < 1 || hiz.height < 1)
        throw Error("GL: OcclusionPass: no Hi-Z pyramid (create_hiz_texture, HiZBuildPass)");
    if (hiz.reversed != is_reversed(depth))
        throw Error(std::string("GL: OcclusionPass: the matrix is declared ") + clip_depth_name(depth) +
                    " but the Hi-Z pyramid was built from a " + (hiz.reversed ? "reversed" : "forward") +
                    " depth buffer (HiZBuildPass::run's convention)");
}

pp::OcclusionParams make_params(const FrustumPlanes& planes, const HiZTexture& hiz, bool has_margins,
                                bool with_frustum) {
    pp::OcclusionParams params;
    detail::store_planes(planes, params.clip_rows, params.plane_normal_length, params.plane_depth);
    params.has_margins = has_margins ? 1u : 0u;
    params.with_frustum = with_frustum ? 1u : 0u;
    params.screen_width = hiz.width;
    params.screen_height = hiz.height;
    params.hiz_levels = HiZPyramid::level_count(hiz.width, hiz.height);
    return params;
}

/// The program's constants (flag_chain.h's PC_MARGINS, PC_WITH_FRUSTUM): one program each.
std::string defines(bool has_margins, bool with_frustum) {
    return std::string(detail::margins_define(has_margins)) + "#define PC_WITH_FRUSTUM " + (with_frustum ? "1" : "0") +
           "\n";
}

}  // namespace

OcclusionPass::OcclusionPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
OcclusionPass::OcclusionPass(OcclusionPass&&) noexcept = default;
OcclusionPass& OcclusionPass::operator=(OcclusionPass&&) noexcept = default;
OcclusionPass::~OcclusionPass() = default;

void OcclusionPass::run(const PatchBuffers& patches, const Mat4& any_object_to_clip, ClipDepth depth,
                        const HiZTexture& hiz, bool with_frustum) {
    detail::begin_pass("OcclusionPass");
    detail::check_patch_buffers("OcclusionPass", patches);
    check_hiz(hiz, depth);
    const FrustumPlanes planes = make_frustum_planes(any_object_to_clip, depth);  // refuses a contradiction
    if (patches.count == 0) return;
    pp::OcclusionParams params = make_params(planes, hiz, patches.margins != 0, with_frustum);
    glUseProgram(impl_->context.program("occlusion.comp.glsl", defines(patches.margins != 0, with_frustum)));
    detail::bind_patch_buffers(patches);
    glBindTextureUnit(shared::kTextureUnitHiZ, hiz.texture);
    detail::dispatch_patches(impl_->block, params, patches.first, patches.count, shared::kCullGroupSize);
    detail::finish_pass("OcclusionPass");
}

void OcclusionPass::run(const PatchBuffers& patches, const CullView& view, const HiZTexture& hiz, bool with_frustum) {
    run(patches, view.object_to_clip, view.depth, hiz, with_frustum);
}

void OcclusionPass::run(const GpuPatchSource& source, const Mat4& any_object_to_clip, ClipDepth depth,
                        const HiZTexture& hiz, bool with_frustum) {
    detail::begin_pass("OcclusionPass");
    const pp::PatchSourceParams source_params = detail::check_patch_source("OcclusionPass", impl_->context, source);
    check_hiz(hiz, depth);
    const FrustumPlanes planes = make_frustum_planes(any_object_to_clip, depth);  // refuses a contradiction
    if (source.count == 0) return;
    pp::OcclusionParams params = make_params(planes, hiz, source.margins != 0, with_frustum);
    glUseProgram(impl_->context.program(
        "occlusion.comp.glsl", detail::patch_source_defines(source) + defines(source.margins != 0, with_frustum)));
    detail::bind_patch_source(*impl_, source, source_params);
    glBindTextureUnit(shared::kTextureUnitHiZ, hiz.texture);
    detail::dispatch_patches(impl_->block, params, source.first, source.count, shared::kCullGroupSize);
    detail::finish_pass("OcclusionPass");
}

void OcclusionPass::run(const GpuPatchSource& source, const CullView& view, const HiZTexture& hiz, bool with_frustum) {
    run(source, view.object_to_clip, view.depth, hiz, with_frustum);
}

}  // namespace patchcull::gl
