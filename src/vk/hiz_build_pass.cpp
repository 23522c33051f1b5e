// HiZBuildPass (patchcull/vk/vk_passes.h): Niessner & Loop's pyramid on Vulkan,
// shaders/hiz_build.comp.glsl, one dispatch per level with an image barrier between levels.
#include <bit>
#include <string>

#include "patchcull/core/hiz.h"
#include "vk_common.h"

namespace patchcull::vk {

static_assert(sizeof(pp::HiZBuildParams) == 32);

VkImageCreateInfo hiz_image_create_info(int width, int height) {
    if (width < 1 || height < 1 || width > 8192 || height > 8192)
        throw Error("Vulkan: hiz_image_create_info: the depth buffer is " + std::to_string(width) + " x " +
                    std::to_string(height) + " (each 1..8192)");
    VkImageCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = VK_FORMAT_R32_SFLOAT;
    info.extent = {std::bit_ceil(static_cast<std::uint32_t>((width + 1) / 2)),
                   std::bit_ceil(static_cast<std::uint32_t>((height + 1) / 2)), 1};
    info.mipLevels = static_cast<std::uint32_t>(HiZPyramid::level_count(width, height));
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    return info;
}

HiZBuildPass::HiZBuildPass(PassContext& context) : context_(&context.impl()) {}

void HiZBuildPass::run(VkCommandBuffer cmd, const DepthImage& depth, HiZImage& hiz, ClipDepth convention) {
    PassContext::Impl& context = *context_;
    if (!depth.view) throw Error("Vulkan: HiZBuildPass: no depth view");
    if (depth.format != VK_FORMAT_D32_SFLOAT && depth.format != VK_FORMAT_D32_SFLOAT_S8_UINT)
        throw Error("Vulkan: HiZBuildPass: depth format " + std::to_string(static_cast<int>(depth.format)) +
                    " is not VK_FORMAT_D32_SFLOAT or VK_FORMAT_D32_SFLOAT_S8_UINT");
    if (!hiz.image || !hiz.all_levels || hiz.width < 1 || hiz.height < 1)
        throw Error("Vulkan: HiZBuildPass: no Hi-Z image (hiz_image_create_info)");
    const int levels = HiZPyramid::level_count(hiz.width, hiz.height);
    for (int l = 0; l < levels; ++l)
        if (!hiz.level_views[static_cast<std::size_t>(l)])
            throw Error("Vulkan: HiZBuildPass: no view of level " + std::to_string(l) + " of the Hi-Z image");
    const detail::Pipeline& p =
        context.pipeline("hiz_build.comp.glsl", "",
                         {{shared::kImageUnitHiZOut, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE},
                          {shared::kTextureUnitDepth, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
                          {shared::kTextureUnitHiZ, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER}},
                         sizeof(pp::HiZBuildParams));
    hiz.reversed = is_reversed(convention);
    context.vk.CmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    pp::HiZBuildParams params;
    int source_w = hiz.width, source_h = hiz.height;
    for (int l = 0; l < levels; ++l) {
        const int out_w = (source_w + 1) / 2, out_h = (source_h + 1) / 2;
        const VkDescriptorImageInfo images[3] = {
            {VK_NULL_HANDLE, hiz.level_views[static_cast<std::size_t>(l)], VK_IMAGE_LAYOUT_GENERAL},
            {context.sampler, depth.view, depth.layout},
            {context.sampler, hiz.all_levels, VK_IMAGE_LAYOUT_GENERAL}};
        const std::uint32_t binding[3] = {shared::kImageUnitHiZOut, shared::kTextureUnitDepth, shared::kTextureUnitHiZ};
        const VkDescriptorType type[3] = {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                          VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER};
        VkWriteDescriptorSet writes[3]{};
        for (int i = 0; i < 3; ++i) {
            writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
            writes[i].dstBinding = binding[i];
            writes[i].descriptorCount = 1;
            writes[i].descriptorType = type[i];
            writes[i].pImageInfo = &images[i];
        }
        context.vk.CmdPushDescriptorSetKHR(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 3, writes);
        params.from_depth = l == 0 ? 1u : 0u;
        params.source_level = l == 0 ? 0 : l - 1;
        params.source_width = source_w;
        params.source_height = source_h;
        params.out_width = out_w;
        params.out_height = out_h;
        params.reversed = hiz.reversed ? 1u : 0u;
        params.unorm24 = 0u;
        context.vk.CmdPushConstants(cmd, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof params, &params);
        context.vk.CmdDispatch(
            cmd, (static_cast<std::uint32_t>(out_w) + shared::kHiZGroupSize - 1) / shared::kHiZGroupSize,
            (static_cast<std::uint32_t>(out_h) + shared::kHiZGroupSize - 1) / shared::kHiZGroupSize, 1);
        if (l + 1 < levels) {
            // The next level reads this one.
            VkImageMemoryBarrier barrier{};
            barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
            barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
            barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
            barrier.oldLayout = VK_IMAGE_LAYOUT_GENERAL;
            barrier.newLayout = VK_IMAGE_LAYOUT_GENERAL;
            barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            barrier.image = hiz.image;
            barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, static_cast<std::uint32_t>(l), 1, 0, 1};
            context.vk.CmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, nullptr, 0, nullptr, 1, &barrier);
        }
        source_w = out_w;
        source_h = out_h;
    }
    context.barrier_after(cmd);
}

}  // namespace patchcull::vk
