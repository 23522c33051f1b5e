// The headless renderer's buffers and images (renderer_resources.h).
#include "renderer_resources.h"

#include <algorithm>
#include <string>

#include "patchcull/core/error.h"

namespace patchcull::vk::detail {

void check_renderer(VkResult result, const char* what) {
    if (result != VK_SUCCESS)
        throw Error(std::string("Vulkan: CullRenderer: ") + what + " failed (VkResult " +
                    std::to_string(static_cast<int>(result)) + ")");
}

void HostBuffer::release() {
    const VkDevice d = device_->device();
    if (mapped_) vkUnmapMemory(d, memory_);
    if (buffer_) vkDestroyBuffer(d, buffer_, nullptr);
    if (memory_) vkFreeMemory(d, memory_, nullptr);
    mapped_ = nullptr;
    buffer_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
    size_ = 0;
}

void HostBuffer::reserve(std::size_t bytes) {
    bytes = std::max<std::size_t>(bytes, 256);
    if (buffer_ && bytes <= size_) return;
    release();
    const VkDevice d = device_->device();
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = bytes;
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                 VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check_renderer(vkCreateBuffer(d, &info, nullptr, &buffer_), "vkCreateBuffer");
    VkMemoryRequirements requirements{};
    vkGetBufferMemoryRequirements(d, buffer_, &requirements);
    VkMemoryAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = device_->memory_type(
        requirements.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    check_renderer(vkAllocateMemory(d, &allocate, nullptr, &memory_), "vkAllocateMemory");
    check_renderer(vkBindBufferMemory(d, buffer_, memory_, 0), "vkBindBufferMemory");
    check_renderer(vkMapMemory(d, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
    size_ = bytes;
}

void HostBuffer::assign(const void* data, std::size_t bytes) {
    reserve(bytes);
    if (data && bytes)
        std::memcpy(mapped_, data, bytes);
    else if (bytes)
        std::memset(mapped_, 0, bytes);
}

void Image::create(const VkImageCreateInfo& info, VkImageAspectFlags aspect) {
    release();
    const VkDevice d = device_->device();
    check_renderer(vkCreateImage(d, &info, nullptr, &image_), "vkCreateImage");
    VkMemoryRequirements requirements{};
    vkGetImageMemoryRequirements(d, image_, &requirements);
    VkMemoryAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = device_->memory_type(requirements.memoryTypeBits, 0);
    check_renderer(vkAllocateMemory(d, &allocate, nullptr, &memory_), "vkAllocateMemory (image)");
    check_renderer(vkBindImageMemory(d, image_, memory_, 0), "vkBindImageMemory");
    format_ = info.format;
    aspect_ = aspect;
    level_views_.assign(info.mipLevels, VK_NULL_HANDLE);
    VkImageViewCreateInfo view{};
    view.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    view.image = image_;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format_;
    view.subresourceRange = {aspect, 0, info.mipLevels, 0, 1};
    check_renderer(vkCreateImageView(d, &view, nullptr, &view_), "vkCreateImageView");
}

VkImageView Image::level_view(std::uint32_t level) {
    if (level >= level_views_.size()) throw Error("Vulkan: CullRenderer: image level out of range (internal)");
    if (!level_views_[level]) {
        VkImageViewCreateInfo view{};
        view.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
        view.image = image_;
        view.viewType = VK_IMAGE_VIEW_TYPE_2D;
        view.format = format_;
        view.subresourceRange = {aspect_, level, 1, 0, 1};
        check_renderer(vkCreateImageView(device_->device(), &view, nullptr, &level_views_[level]),
                       "vkCreateImageView (level)");
    }
    return level_views_[level];
}

void Image::release() {
    const VkDevice d = device_->device();
    for (VkImageView v : level_views_)
        if (v) vkDestroyImageView(d, v, nullptr);
    level_views_.clear();
    if (view_) vkDestroyImageView(d, view_, nullptr);
    if (image_) vkDestroyImage(d, image_, nullptr);
    if (memory_) vkFreeMemory(d, memory_, nullptr);
    view_ = VK_NULL_HANDLE;
    image_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
}

void to_general(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect) {
    VkImageMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    barrier.srcAccessMask = 0;
    barrier.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    barrier.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {aspect, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &barrier);
}

void full_barrier(VkCommandBuffer cmd) {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &barrier, 0,
                         nullptr, 0, nullptr);
}

}  // namespace patchcull::vk::detail
