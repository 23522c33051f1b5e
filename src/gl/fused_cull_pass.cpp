// FusedCullPass (patchcull/gl/gl_passes.h): the frustum, cone back-patch and Hi-Z tests in one
// dispatch, shaders/fused_cull.comp.glsl (ncone compiled with PATCHCULL_NCONE).
#include "pass_common.h"

namespace patchcull::gl {

struct FusedCullPass::Impl : detail::PassState {
    using PassState::PassState;
};

FusedCullPass::FusedCullPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
FusedCullPass::FusedCullPass(FusedCullPass&&) noexcept = default;
FusedCullPass& FusedCullPass::operator=(FusedCullPass&&) noexcept = default;
FusedCullPass::~FusedCullPass() = default;

void FusedCullPass::run(const PatchBuffers& patches, std::uint32_t tests, const Mat4& any_object_to_clip,
                        ClipDepth depth, BackpatchMethod method, Vec3 eye, const HiZTexture* hiz) {
    detail::begin_pass("FusedCullPass");
    detail::check_patch_buffers("FusedCullPass", patches);
    if (tests & ~(shared::kCullFrustum | shared::kCullBackPatch | shared::kCullOcclusion))
        throw Error("GL: FusedCullPass: tests must be kCullFrustum, kCullBackPatch and kCullOcclusion bits");
    const bool backpatch = (tests & shared::kCullBackPatch) != 0;
    const bool occlusion = (tests & shared::kCullOcclusion) != 0;
    if (backpatch && method != BackpatchMethod::tcone && method != BackpatchMethod::ncone)
        throw Error(std::string("GL: FusedCullPass: ") + backpatch_method_name(method) +
                    " is not fused (its own pass runs it: gl_backpatch_passes.h)");
    if (occlusion && (!hiz || !glIsTexture(hiz->texture) || hiz->width < 1 || hiz->height < 1))
        throw Error("GL: FusedCullPass: the occlusion test needs a Hi-Z pyramid (create_hiz_texture, HiZBuildPass)");
    if (occlusion && hiz->reversed != is_reversed(depth))
        throw Error(std::string("GL: FusedCullPass: the matrix is declared ") + clip_depth_name(depth) +
                    " but the Hi-Z pyramid was built from a " + (hiz->reversed ? "reversed" : "forward") +
                    " depth buffer (HiZBuildPass::run's convention)");
    const FrustumPlanes planes = make_frustum_planes(any_object_to_clip, depth);  // refuses a contradiction
    if (patches.count == 0 || tests == 0) return;
    pp::FusedCullParams params;
    detail::store_planes(planes, params.clip_rows, params.plane_normal_length, params.plane_depth);
    params.eye = {eye.x, eye.y, eye.z, 1.0f};
    params.has_margins = patches.margins ? 1u : 0u;
    params.tests = tests;
    if (occlusion) {
        params.screen_width = hiz->width;
        params.screen_height = hiz->height;
        params.hiz_levels = HiZPyramid::level_count(hiz->width, hiz->height);
    }
    params.zero = 0.0f;
    const bool ncone = backpatch && method == BackpatchMethod::ncone;
    glUseProgram(impl_->context.program("fused_cull.comp.glsl", ncone ? "#define PATCHCULL_NCONE 1\n" : ""));
    detail::bind_patch_buffers(patches);
    if (occlusion) glBindTextureUnit(shared::kTextureUnitHiZ, hiz->texture);
    detail::dispatch_patches(impl_->block, params, patches.first, patches.count, shared::kCullGroupSize);
    detail::finish_pass("FusedCullPass");
}

void FusedCullPass::run(const PatchBuffers& patches, std::uint32_t tests, const CullView& view, BackpatchMethod method,
                        const HiZTexture* hiz) {
    if (!view.has_eye) tests &= ~shared::kCullBackPatch;
    run(patches, tests, view.object_to_clip, view.depth, method, view.eye, hiz);
}

}  // namespace patchcull::gl
