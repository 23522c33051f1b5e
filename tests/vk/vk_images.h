// Images for the Vulkan Hi-Z tests: a test image with its memory and views, layout transitions,
// and the pyramid of a depth array built by HiZBuildPass (read back, or kept for a pass to use).
#pragma once

#include <functional>
#include <stdexcept>
#include <vector>

#include "patchcull/core/hiz.h"
#include "vk/vk_test_util.h"

namespace patchcull::vk::test {

inline std::uint32_t memory_type(VkPhysicalDevice physical_device, std::uint32_t bits) {
    VkPhysicalDeviceMemoryProperties memory{};
    vkGetPhysicalDeviceMemoryProperties(physical_device, &memory);
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
        if (bits & (1u << i)) return i;
    return 0;
}

// An image with its memory, destroyed at scope end.
struct TestImage {
    explicit TestImage(const VkImageCreateInfo& info) {
        Context& c = Context::get();
        if (vkCreateImage(c.device(), &info, nullptr, &image) != VK_SUCCESS) throw std::runtime_error("vkCreateImage");
        VkMemoryRequirements req{};
        vkGetImageMemoryRequirements(c.device(), image, &req);
        VkMemoryAllocateInfo allocate{};
        allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        allocate.allocationSize = req.size;
        allocate.memoryTypeIndex = memory_type(c.physical_device(), req.memoryTypeBits);
        if (vkAllocateMemory(c.device(), &allocate, nullptr, &memory) != VK_SUCCESS)
            throw std::runtime_error("vkAllocateMemory");
        vkBindImageMemory(c.device(), image, memory, 0);
    }
    ~TestImage() {
        const VkDevice d = Context::get().device();
        for (VkImageView v : views) vkDestroyImageView(d, v, nullptr);
        vkDestroyImage(d, image, nullptr);
        vkFreeMemory(d, memory, nullptr);
    }
    VkImageView view(VkFormat format, VkImageAspectFlags aspect, std::uint32_t base_level, std::uint32_t levels) {
        VkImageViewCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
        info.image = image;
        info.viewType = VK_IMAGE_VIEW_TYPE_2D;
        info.format = format;
        info.subresourceRange = {aspect, base_level, levels, 0, 1};
        VkImageView v = VK_NULL_HANDLE;
        vkCreateImageView(Context::get().device(), &info, nullptr, &v);
        views.push_back(v);
        return v;
    }
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    std::vector<VkImageView> views;
};

inline void transition(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, std::uint32_t levels,
                       VkImageLayout from, VkImageLayout to, VkAccessFlags src_access, VkAccessFlags dst_access,
                       VkPipelineStageFlags src_stage, VkPipelineStageFlags dst_stage) {
    VkImageMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcAccessMask = src_access;
    b.dstAccessMask = dst_access;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, levels, 0, 1};
    vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

// Builds the pyramid of depths (w x h, depth image row r = array row r) on Vulkan, records then(cmd,
// pyramid) after the build in the same command buffer, and reads every level back in
// HiZPyramid::data()'s layout.
inline std::vector<float> vk_pyramid(Context& vk, const std::vector<float>& depths, int w, int h, ClipDepth convention,
                                     bool* reversed,
                                     const std::function<void(VkCommandBuffer, const HiZImage&)>& then = {}) {
    VkImageCreateInfo depth_info{};
    depth_info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    depth_info.imageType = VK_IMAGE_TYPE_2D;
    depth_info.format = VK_FORMAT_D32_SFLOAT;
    depth_info.extent = {static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h), 1};
    depth_info.mipLevels = 1;
    depth_info.arrayLayers = 1;
    depth_info.samples = VK_SAMPLE_COUNT_1_BIT;
    depth_info.tiling = VK_IMAGE_TILING_OPTIMAL;
    depth_info.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    TestImage depth(depth_info);
    DepthImage depth_image{depth.view(VK_FORMAT_D32_SFLOAT, VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1),
                           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_FORMAT_D32_SFLOAT};
    const VkImageCreateInfo hiz_info = hiz_image_create_info(w, h);
    TestImage pyramid(hiz_info);
    HiZImage hiz;
    hiz.image = pyramid.image;
    hiz.all_levels = pyramid.view(VK_FORMAT_R32_SFLOAT, VK_IMAGE_ASPECT_COLOR_BIT, 0, hiz_info.mipLevels);
    for (std::uint32_t l = 0; l < hiz_info.mipLevels; ++l)
        hiz.level_views[l] = pyramid.view(VK_FORMAT_R32_SFLOAT, VK_IMAGE_ASPECT_COLOR_BIT, l, 1);
    hiz.width = w;
    hiz.height = h;

    HiZPyramid layout(w, h);
    HostBuffer upload(depths.size() * 4);
    upload.write(depths.data(), depths.size() * 4);
    HostBuffer readback(layout.size() * 4);
    HiZBuildPass pass(vk.passes());
    vk.submit([&](VkCommandBuffer cmd) {
        transition(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
        VkBufferImageCopy copy{};
        copy.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
        copy.imageExtent = depth_info.extent;
        vkCmdCopyBufferToImage(cmd, upload.range().buffer, depth.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
        transition(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                   VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT,
                   VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
        transition(cmd, pyramid.image, VK_IMAGE_ASPECT_COLOR_BIT, hiz_info.mipLevels, VK_IMAGE_LAYOUT_UNDEFINED,
                   VK_IMAGE_LAYOUT_GENERAL, 0, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
        pass.run(cmd, depth_image, hiz, convention);
        if (then) then(cmd, hiz);
        transition(cmd, pyramid.image, VK_IMAGE_ASPECT_COLOR_BIT, hiz_info.mipLevels, VK_IMAGE_LAYOUT_GENERAL,
                   VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT,
                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
        for (int l = 0; l < layout.levels(); ++l) {
            VkBufferImageCopy back{};
            back.bufferOffset = layout.level(l).offset * 4;
            back.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, static_cast<std::uint32_t>(l), 0, 1};
            back.imageExtent = {static_cast<std::uint32_t>(layout.level(l).width),
                                static_cast<std::uint32_t>(layout.level(l).height), 1};
            vkCmdCopyImageToBuffer(cmd, pyramid.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.range().buffer, 1,
                                   &back);
        }
    });
    *reversed = hiz.reversed;
    return readback.read<float>(layout.size());
}

}  // namespace patchcull::vk::test
