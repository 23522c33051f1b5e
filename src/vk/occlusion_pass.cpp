// OcclusionPass (patchcull/vk/vk_passes.h): cull_occlusion_scalar on Vulkan against a pyramid of
// HiZBuildPass, shaders/occlusion.comp.glsl; its 144-byte parameter block is the context's uniform
// buffer (shaders/api.h), updated before each dispatch.
#include <algorithm>
#include <string>

#include "vk_common.h"

namespace patchcull::vk {

OcclusionPass::OcclusionPass(PassContext& context) : context_(&context.impl()) {}

void OcclusionPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, const Mat4& object_to_clip, ClipDepth depth,
                        const HiZImage& hiz, bool with_frustum) {
    const char* who = "OcclusionPass";
    PassContext::Impl& context = *context_;
    const VkDeviceSize end = patches.first + patches.count;
    context.check_range(who, "control-point", patches.control_points, end * 256, false);
    context.check_range(who, "flag", patches.flags, end * 4, false);
    context.check_range(who, "margin", patches.margins, end * 4, true);
    if (!hiz.all_levels || hiz.width < 1 || hiz.height < 1)
        throw Error("Vulkan: OcclusionPass: no Hi-Z pyramid (hiz_image_create_info, HiZBuildPass)");
    if (hiz.reversed != is_reversed(depth))
        throw Error(std::string("Vulkan: OcclusionPass: the matrix is declared ") + clip_depth_name(depth) +
                    " but the Hi-Z pyramid was built from a " + (hiz.reversed ? "reversed" : "forward") +
                    " depth buffer (HiZBuildPass::run's convention)");
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, depth);  // refuses a contradiction
    if (patches.count == 0) return;
    const detail::Pipeline& p = context.pipeline("occlusion.comp.glsl", "",
                                                 {shared::kBindingControlPoints,
                                                  shared::kBindingCullFlags,
                                                  shared::kBindingMaxDisplacement,
                                                  {api::kParamsBinding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                                                  {api::kTextureHiZBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER}},
                                                 0);
    pp::OcclusionParams params;
    detail::store_planes(planes, params);
    params.has_margins = patches.margins.buffer ? 1u : 0u;
    params.with_frustum = with_frustum ? 1u : 0u;
    params.screen_width = hiz.width;
    params.screen_height = hiz.height;
    params.hiz_levels = HiZPyramid::level_count(hiz.width, hiz.height);

    const detail::Binding bindings[] = {{shared::kBindingControlPoints, patches.control_points},
                                        {shared::kBindingCullFlags, patches.flags},
                                        {shared::kBindingMaxDisplacement, patches.margins}};
    context.record_uniform(cmd, p, bindings, 3, hiz.all_levels, params, patches.first, patches.count,
                           shared::kCullGroupSize);
}

void OcclusionPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, const CullView& view, const HiZImage& hiz,
                        bool with_frustum) {
    run(cmd, patches, view.object_to_clip, view.depth, hiz, with_frustum);
}

}  // namespace patchcull::vk
