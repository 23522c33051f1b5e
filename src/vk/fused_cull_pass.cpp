// FusedCullPass (patchcull/vk/vk_passes.h): the frustum, cone back-patch and Hi-Z tests in one
// dispatch on Vulkan, shaders/fused_cull.comp.glsl (ncone: its PATCHCULL_NCONE module); its
// 160-byte parameter block is the context's uniform buffer (shaders/api.h).
#include <algorithm>
#include <string>

#include "vk_common.h"

namespace patchcull::vk {

static_assert(sizeof(pp::FusedCullParams) == 160);

FusedCullPass::FusedCullPass(PassContext& context) : context_(&context.impl()) {}

void FusedCullPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, std::uint32_t tests,
                        const Mat4& object_to_clip, ClipDepth depth, BackpatchMethod method, Vec3 eye,
                        const HiZImage& hiz) {
    const char* who = "FusedCullPass";
    PassContext::Impl& context = *context_;
    const VkDeviceSize end = patches.first + patches.count;
    context.check_range(who, "control-point", patches.control_points, end * 256, false);
    context.check_range(who, "flag", patches.flags, end * 4, false);
    context.check_range(who, "margin", patches.margins, end * 4, true);
    if (tests & ~(kCullFrustum | kCullBackPatch | kCullOcclusion))
        throw Error("Vulkan: FusedCullPass: tests must be kCullFrustum, kCullBackPatch and kCullOcclusion bits");
    const bool backpatch = (tests & kCullBackPatch) != 0;
    const bool occlusion = (tests & kCullOcclusion) != 0;
    if (backpatch && method != BackpatchMethod::tcone && method != BackpatchMethod::ncone)
        throw Error(std::string("Vulkan: FusedCullPass: ") + backpatch_method_name(method) +
                    " is not fused (its own pass runs it)");
    if (!hiz.all_levels || hiz.width < 1 || hiz.height < 1)
        throw Error("Vulkan: FusedCullPass: no Hi-Z pyramid (bound in every run, read with kCullOcclusion)");
    if (occlusion && hiz.reversed != is_reversed(depth))
        throw Error(std::string("Vulkan: FusedCullPass: the matrix is declared ") + clip_depth_name(depth) +
                    " but the Hi-Z pyramid was built from a " + (hiz.reversed ? "reversed" : "forward") +
                    " depth buffer (HiZBuildPass::run's convention)");
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, depth);  // refuses a contradiction
    if (patches.count == 0 || tests == 0) return;
    const bool ncone = backpatch && method == BackpatchMethod::ncone;
    const detail::Pipeline& p = context.pipeline("fused_cull.comp.glsl", ncone ? "PATCHCULL_NCONE" : "",
                                                 {shared::kBindingControlPoints,
                                                  shared::kBindingCullFlags,
                                                  shared::kBindingMaxDisplacement,
                                                  {api::kTextureHiZBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
                                                  {api::kParamsBinding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER}},
                                                 0);
    pp::FusedCullParams params;
    detail::store_planes(planes, params);
    params.eye = {eye.x, eye.y, eye.z, 1.0f};
    params.has_margins = patches.margins.buffer ? 1u : 0u;
    params.tests = tests;
    if (occlusion) {
        params.screen_width = hiz.width;
        params.screen_height = hiz.height;
        params.hiz_levels = HiZPyramid::level_count(hiz.width, hiz.height);
    }
    params.zero = 0.0f;

    const detail::Binding bindings[] = {{shared::kBindingControlPoints, patches.control_points},
                                        {shared::kBindingCullFlags, patches.flags},
                                        {shared::kBindingMaxDisplacement, patches.margins}};
    context.record_uniform(cmd, p, bindings, 3, hiz.all_levels, params, patches.first, patches.count,
                           shared::kCullGroupSize);
}

}  // namespace patchcull::vk
