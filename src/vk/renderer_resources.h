// The headless renderer's memory (vk_renderer.h), not a public header: host-visible buffers
// mapped for their lifetime, and 2D images with one view, all on a HeadlessDevice.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstring>
#include <vector>

#include "patchcull/vk/vk_device.h"
#include "patchcull/vk/vk_passes.h"

namespace patchcull::vk::detail {

/// A buffer in host-visible, coherent memory, mapped; usable as storage, indirect, transfer
/// source and destination. Grows by resize (contents lost).
class HostBuffer {
public:
    explicit HostBuffer(HeadlessDevice& device) : device_(&device) {}
    ~HostBuffer() { release(); }
    HostBuffer(const HostBuffer&) = delete;
    HostBuffer& operator=(const HostBuffer&) = delete;

    /// At least bytes bytes (and 256): a new buffer when the current one is smaller.
    void reserve(std::size_t bytes);
    /// reserve(bytes), then copies data (bytes of it; null: zeros).
    void assign(const void* data, std::size_t bytes);
    BufferRange range(std::size_t bytes) const { return {buffer_, 0, bytes}; }
    BufferRange whole() const { return {buffer_, 0, size_}; }
    VkBuffer buffer() const { return buffer_; }
    std::size_t size() const { return size_; }
    void* data() const { return mapped_; }
    template <class T>
    std::vector<T> read(std::size_t count) const {
        std::vector<T> out(count);
        if (count) std::memcpy(out.data(), mapped_, count * sizeof(T));
        return out;
    }

private:
    void release();
    HeadlessDevice* device_;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    void* mapped_ = nullptr;
    std::size_t size_ = 0;
};

/// A 2D image in device memory (any type it allows) with one view of all its levels; created in
/// VK_IMAGE_LAYOUT_UNDEFINED (the owner moves it to GENERAL).
class Image {
public:
    explicit Image(HeadlessDevice& device) : device_(&device) {}
    ~Image() { release(); }
    Image(const Image&) = delete;
    Image& operator=(const Image&) = delete;

    void create(const VkImageCreateInfo& info, VkImageAspectFlags aspect);
    void release();
    VkImage image() const { return image_; }
    VkImageView view() const { return view_; }
    /// A view of one mip level (owned by the image), e.g. for a storage binding.
    VkImageView level_view(std::uint32_t level);
    bool exists() const { return image_ != VK_NULL_HANDLE; }

private:
    HeadlessDevice* device_;
    VkImage image_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkImageView view_ = VK_NULL_HANDLE;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
    VkImageAspectFlags aspect_ = 0;
    std::vector<VkImageView> level_views_;
};

/// "Vulkan: CullRenderer: <what> failed (VkResult n)" unless VK_SUCCESS.
void check_renderer(VkResult result, const char* what);

/// One image barrier of every level and layer: from UNDEFINED to GENERAL (contents discarded).
void to_general(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect);

/// A full memory barrier: every earlier write available and visible to every later access, every
/// later access after every earlier one.
void full_barrier(VkCommandBuffer cmd);

}  // namespace patchcull::vk::detail
