// OcclusionPass (patchcull/gl/gl_passes.h): cull_occlusion_scalar on the GPU against a Hi-Z
// pyramid, shaders/occlusion.comp.glsl.
#include "pass_common.h"

namespace patchcull::gl {

struct OcclusionPass::Impl : detail::PassState {
    using PassState::PassState;
};

OcclusionPass::OcclusionPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
OcclusionPass::OcclusionPass(OcclusionPass&&) noexcept = default;
OcclusionPass& OcclusionPass::operator=(OcclusionPass&&) noexcept = default;
OcclusionPass::~OcclusionPass() = default;

void OcclusionPass::run(const PatchBuffers& patches, const Mat4& any_object_to_clip, ClipDepth depth,
                        const HiZTexture& hiz, bool with_frustum) {
    detail::begin_pass("OcclusionPass");
    detail::check_patch_buffers("OcclusionPass", patches);
    if (!glIsTexture(hiz.texture) || hiz.width < 1 || hiz.height < 1)
        throw Error("GL: OcclusionPass: no Hi-Z pyramid (create_hiz_texture, HiZBuildPass)");
    if (hiz.reversed != is_reversed(depth))
        throw Error(std::string("GL: OcclusionPass: the matrix is declared ") + clip_depth_name(depth) +
                    " but the Hi-Z pyramid was built from a " + (hiz.reversed ? "reversed" : "forward") +
                    " depth buffer (HiZBuildPass::run's convention)");
    const FrustumPlanes planes = make_frustum_planes(any_object_to_clip, depth);  // refuses a contradiction
    if (patches.count == 0) return;
    pp::OcclusionParams params;
    detail::store_planes(planes, params.clip_rows, params.plane_normal_length, params.plane_depth);
    params.has_margins = patches.margins ? 1u : 0u;
    params.with_frustum = with_frustum ? 1u : 0u;
    params.screen_width = hiz.width;
    params.screen_height = hiz.height;
    params.hiz_levels = HiZPyramid::level_count(hiz.width, hiz.height);
    glUseProgram(impl_->context.program("occlusion.comp.glsl"));
    detail::bind_patch_buffers(patches);
    glBindTextureUnit(shared::kTextureUnitHiZ, hiz.texture);
    detail::dispatch_patches(impl_->block, params, patches.first, patches.count, shared::kCullGroupSize);
    detail::finish_pass("OcclusionPass");
}

void OcclusionPass::run(const PatchBuffers& patches, const CullView& view, const HiZTexture& hiz, bool with_frustum) {
    run(patches, view.object_to_clip, view.depth, hiz, with_frustum);
}

}  // namespace patchcull::gl
