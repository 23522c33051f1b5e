// The Vulkan Hi-Z build pass (patchcull/vk/vk_passes.h's HiZBuildPass) on lavapipe with the
// validation layers on: from a D32_SFLOAT depth image holding the same depths as an array, every
// level's texels equal HiZPyramid::build's bit for bit, for odd and even sizes, in the forward and
// reversed conventions (keys -depth), and the pass sets HiZImage::reversed.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <stdexcept>

#include "patchcull/core/hiz.h"
#include "vk/vk_test_util.h"

using namespace patchcull;
using namespace patchcull::vk;
using namespace patchcull::vk::test;

namespace {

std::uint32_t memory_type(VkPhysicalDevice physical_device, std::uint32_t bits) {
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

void transition(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, std::uint32_t levels, VkImageLayout from,
                VkImageLayout to, VkAccessFlags src_access, VkAccessFlags dst_access, VkPipelineStageFlags src_stage,
                VkPipelineStageFlags dst_stage) {
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

// Depths with structure (planes at several depths, a gradient) and noise; exact 0 and 1 too.
std::vector<float> test_depths(int w, int h, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> d(static_cast<std::size_t>(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float v = (x / 7 + y / 5) % 3 == 0 ? 0.25f + 0.5f * u(rng) : static_cast<float>(x + y) / (w + h);
            if ((x * 31 + y * 17) % 23 == 0) v = 1.0f;
            if ((x * 13 + y * 29) % 19 == 0) v = 0.0f;
            d[static_cast<std::size_t>(y) * w + x] = v;
        }
    return d;
}

// Builds the pyramid of depths on Vulkan and reads every level back in HiZPyramid::data()'s layout.
std::vector<float> vk_pyramid(Context& vk, const std::vector<float>& depths, int w, int h, ClipDepth convention,
                              bool* reversed) {
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

class VkHiZ : public VkTest {};

}  // namespace

TEST_F(VkHiZ, PyramidEqualsCpuBuildBitForBit) {
    struct Size {
        int w, h;
    };
    for (const Size s : {Size{37, 23}, Size{64, 48}, Size{1, 5}, Size{200, 3}})
        for (const ClipDepth convention : {ClipDepth::zero_to_one, ClipDepth::reversed}) {
            const std::vector<float> depths = test_depths(s.w, s.h, static_cast<std::uint32_t>(s.w * 100 + s.h));
            bool reversed = false;
            const std::vector<float> gpu = vk_pyramid(vk(), depths, s.w, s.h, convention, &reversed);
            HiZPyramid cpu;
            cpu.build(depths.data(), s.w, s.h, convention);
            EXPECT_EQ(reversed, is_reversed(convention));
            ASSERT_EQ(gpu.size(), cpu.size());
            for (std::size_t i = 0; i < gpu.size(); ++i) {
                std::uint32_t a, b;
                std::memcpy(&a, &gpu[i], 4);
                std::memcpy(&b, &cpu.data()[i], 4);
                ASSERT_EQ(a, b) << s.w << "x" << s.h << " " << clip_depth_name(convention) << " texel " << i
                                << ": Vulkan " << gpu[i] << ", CPU " << cpu.data()[i];
            }
        }
}
