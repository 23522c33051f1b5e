// FusedCullPass (patchcull/gl/gl_passes.h): the frustum, cone back-patch and Hi-Z tests in one
// dispatch, shaders/fused_cull.comp.glsl (ncone compiled with PATCHCULL_NCONE; over a
// GpuPatchSource with patch_source_defines as well).
#include "pass_common.h"

namespace patchcull::gl {

struct FusedCullPass::Impl : detail::PassState {
    using PassState::PassState;
};

FusedCullPass::FusedCullPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
FusedCullPass::FusedCullPass(FusedCullPass&&) noexcept = default;
FusedCullPass& FusedCullPass::operator=(FusedCullPass&&) noexcept = default;
FusedCullPass::~FusedCullPass() = default;

namespace {

// The checks of both runs (after the buffers'), then the planes and the parameter block.
pp::FusedCullParams fused_params(std::uint32_t tests, const Mat4& any_object_to_clip, ClipDepth depth,
                                 BackpatchMethod method, Vec3 eye, const HiZTexture* hiz, bool has_margins) {
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
    pp::FusedCullParams params;
    detail::store_planes(planes, params.clip_rows, params.plane_normal_length, params.plane_depth);
    params.eye = {eye.x, eye.y, eye.z, 1.0f};
    params.has_margins = has_margins ? 1u : 0u;
    params.tests = tests;
    if (occlusion) {
        params.screen_width = hiz->width;
        params.screen_height = hiz->height;
        params.hiz_levels = HiZPyramid::level_count(hiz->width, hiz->height);
    }
    params.zero = 0.0f;
    return params;
}

}  // namespace

void FusedCullPass::run(const PatchBuffers& patches, std::uint32_t tests, const Mat4& any_object_to_clip,
                        ClipDepth depth, BackpatchMethod method, Vec3 eye, const HiZTexture* hiz) {
    detail::begin_pass("FusedCullPass");
    detail::check_patch_buffers("FusedCullPass", patches);
    pp::FusedCullParams params = fused_params(tests, any_object_to_clip, depth, method, eye, hiz, patches.margins != 0);
    if (patches.count == 0 || tests == 0) return;
    const bool ncone = (tests & shared::kCullBackPatch) != 0 && method == BackpatchMethod::ncone;
    glUseProgram(impl_->context.program(
        "fused_cull.comp.glsl",
        std::string(ncone ? "#define PATCHCULL_NCONE 1\n" : "") + detail::margins_define(patches.margins != 0)));
    detail::bind_patch_buffers(patches);
    if (tests & shared::kCullOcclusion) glBindTextureUnit(shared::kTextureUnitHiZ, hiz->texture);
    detail::dispatch_patches(impl_->block, params, patches.first, patches.count, shared::kCullGroupSize);
    detail::finish_pass("FusedCullPass");
}

void FusedCullPass::run(const GpuPatchSource& source, std::uint32_t tests, const Mat4& any_object_to_clip,
                        ClipDepth depth, BackpatchMethod method, Vec3 eye, const HiZTexture* hiz) {
    detail::begin_pass("FusedCullPass");
    const pp::PatchSourceParams source_params = detail::check_patch_source("FusedCullPass", impl_->context, source);
    pp::FusedCullParams params = fused_params(tests, any_object_to_clip, depth, method, eye, hiz, source.margins != 0);
    if (source.count == 0 || tests == 0) return;
    // A Gregory program has one cone for both methods (its Gregory tangent cone).
    const bool ncone = (tests & shared::kCullBackPatch) != 0 && method == BackpatchMethod::ncone &&
                       source.basis != PatchBasis::gregory;
    const std::string defines = std::string(ncone ? "#define PATCHCULL_NCONE 1\n" : "") +
                                detail::patch_source_defines(source) + detail::margins_define(source.margins != 0);
    glUseProgram(impl_->context.program("fused_cull.comp.glsl", defines));
    detail::bind_patch_source(*impl_, source, source_params);
    if (tests & shared::kCullOcclusion) glBindTextureUnit(shared::kTextureUnitHiZ, hiz->texture);
    detail::dispatch_patches(impl_->block, params, source.first, source.count, shared::kCullGroupSize);
    detail::finish_pass("FusedCullPass");
}

void FusedCullPass::run(const PatchBuffers& patches, std::uint32_t tests, const CullView& view, BackpatchMethod method,
                        const HiZTexture* hiz) {
    if (!view.has_eye) tests &= ~shared::kCullBackPatch;
    run(patches, tests, view.object_to_clip, view.depth, method, view.eye, hiz);
}

void FusedCullPass::run(const GpuPatchSource& source, std::uint32_t tests, const CullView& view, BackpatchMethod method,
                        const HiZTexture* hiz) {
    if (!view.has_eye) tests &= ~shared::kCullBackPatch;
    run(source, tests, view.object_to_clip, view.depth, method, view.eye, hiz);
}

}  // namespace patchcull::gl
