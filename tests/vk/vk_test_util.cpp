// The Vulkan tests' context (vk_test_util.h).
#include "vk/vk_test_util.h"

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>

namespace patchcull::vk::test {

namespace {

void check(VkResult r, const char* what) {
    if (r != VK_SUCCESS)
        throw std::runtime_error(std::string("test context: ") + what + " failed (" +
                                 std::to_string(static_cast<int>(r)) + ")");
}

std::uint32_t memory_type(VkPhysicalDevice physical_device, std::uint32_t bits, VkMemoryPropertyFlags wanted) {
    VkPhysicalDeviceMemoryProperties memory{};
    vkGetPhysicalDeviceMemoryProperties(physical_device, &memory);
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
    throw std::runtime_error("test context: no host-visible coherent memory type");
}

}  // namespace

Context& Context::get() {
    static Context context;
    return context;
}

namespace {
HeadlessDeviceOptions validating() {
    HeadlessDeviceOptions o;
    o.validation = true;  // with synchronization validation (vk_device.h)
    return o;
}
}  // namespace

Context::Context() : device_(validating()) {}

Context::~Context() { passes_.reset(); }

PassContext& Context::passes() {
    if (!passes_) {
        PassContextOptions options;
        options.fma = PassContextOptions::Fma::exact_double;
        passes_ = std::make_unique<PassContext>(device_.physical_device(), device_.device(), options);
    }
    return *passes_;
}

void Context::submit(const std::function<void(VkCommandBuffer)>& record) { device_.submit(record); }

std::vector<std::string> Context::take_messages() {
    std::vector<std::string> messages = device_.take_messages();
    if (std::getenv("PATCHCULL_VK_TEST_PRINT"))
        for (const std::string& m : messages) std::fprintf(stderr, "validation: %s\n", m.c_str());
    return messages;
}

HostBuffer::HostBuffer(std::size_t bytes) : bytes_(bytes) {
    Context& c = Context::get();
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = bytes;
    info.usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check(vkCreateBuffer(c.device(), &info, nullptr, &buffer_), "vkCreateBuffer");
    VkMemoryRequirements requirements{};
    vkGetBufferMemoryRequirements(c.device(), buffer_, &requirements);
    VkMemoryAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = memory_type(c.physical_device(), requirements.memoryTypeBits,
                                           VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    check(vkAllocateMemory(c.device(), &allocate, nullptr, &memory_), "vkAllocateMemory");
    check(vkBindBufferMemory(c.device(), buffer_, memory_, 0), "vkBindBufferMemory");
    check(vkMapMemory(c.device(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
    std::memset(mapped_, 0, bytes);
}

HostBuffer::~HostBuffer() {
    const VkDevice device = Context::get().device();
    vkUnmapMemory(device, memory_);
    vkDestroyBuffer(device, buffer_, nullptr);
    vkFreeMemory(device, memory_, nullptr);
}

void HostBuffer::write(const void* data, std::size_t bytes, std::size_t offset) {
    std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
}

}  // namespace patchcull::vk::test
