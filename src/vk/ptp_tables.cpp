// PassContext::Impl::ptp_tables (vk_common.h): the ptp schedule's tables in a buffer for
// backpatch_ptp.comp.glsl under Vulkan (shaders/ptp_tables.h says why), the words of
// shaders/ptp_schedule.h (ptp_tables_data.h, generated from it at build time), in the std430
// order of ptp_tables.h's block.
#include <cstring>
#include <iterator>
#include <vector>

#include "ptp_tables_data.h"
#include "vk_common.h"

namespace patchcull::vk {

namespace {

// The block's words: each table appended in ptp_tables.h's order.
std::vector<std::uint32_t> table_words() {
    namespace t = detail::ptp;
    static_assert(std::size(t::kPtpPairs) == 66 && std::size(t::kPtpSteps) == 512 &&
                      std::size(t::kPtpStepWeights) == 512 && std::size(t::kPtpDestFirst) == 65 &&
                      std::size(t::kPtpCornerOfDest) == 64 && std::size(t::kPtpCorners) == 4 &&
                      std::size(t::kPtpCornerWeights) == 4 && std::size(t::kPtpMarginWeights) == 64 &&
                      std::size(t::kPtpMarginWeightTerms) == 64 && std::size(t::kPtpEdgePoints) == 16,
                  "shaders/ptp_tables.h's block has these sizes");
    std::vector<std::uint32_t> words;
    auto append = [&words](const auto& table) {
        for (const auto v : table) words.push_back(static_cast<std::uint32_t>(v));
    };
    append(t::kPtpPairs);
    append(t::kPtpSteps);
    append(t::kPtpStepWeights);
    append(t::kPtpDestFirst);
    append(t::kPtpCornerOfDest);
    append(t::kPtpCorners);
    append(t::kPtpCornerWeights);
    append(t::kPtpMarginWeights);
    append(t::kPtpMarginWeightTerms);
    append(t::kPtpEdgePoints);
    return words;
}

}  // namespace

BufferRange PassContext::Impl::ptp_tables() {
    static const std::vector<std::uint32_t> words = table_words();
    const VkDeviceSize bytes = words.size() * sizeof(std::uint32_t);
    if (ptp_table_buffer) return {ptp_table_buffer, 0, bytes};
    // Made in locals and kept only when it is filled: a failure leaves nothing half-built.
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    try {
        VkBufferCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
        info.size = bytes;
        info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
        detail::check_vk(vk.CreateBuffer(device, &info, nullptr, &buffer), "BackpatchPtpPass", "vkCreateBuffer");
        VkMemoryRequirements requirements{};
        vk.GetBufferMemoryRequirements(device, buffer, &requirements);
        VkPhysicalDeviceMemoryProperties properties{};
        vkGetPhysicalDeviceMemoryProperties(physical_device, &properties);
        const VkMemoryPropertyFlags wanted = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        std::uint32_t type = properties.memoryTypeCount;
        for (std::uint32_t i = 0; i < properties.memoryTypeCount && type == properties.memoryTypeCount; ++i)
            if ((requirements.memoryTypeBits & (1u << i)) &&
                (properties.memoryTypes[i].propertyFlags & wanted) == wanted)
                type = i;
        if (type == properties.memoryTypeCount)
            throw Error("Vulkan: BackpatchPtpPass: no host-visible coherent memory for the ptp tables");
        VkMemoryAllocateInfo allocate{};
        allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        allocate.allocationSize = requirements.size;
        allocate.memoryTypeIndex = type;
        detail::check_vk(vk.AllocateMemory(device, &allocate, nullptr, &memory), "BackpatchPtpPass",
                         "vkAllocateMemory");
        detail::check_vk(vk.BindBufferMemory(device, buffer, memory, 0), "BackpatchPtpPass", "vkBindBufferMemory");
        void* mapped = nullptr;
        detail::check_vk(vk.MapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &mapped), "BackpatchPtpPass", "vkMapMemory");
        std::memcpy(mapped, words.data(), bytes);
        vk.UnmapMemory(device, memory);
    } catch (...) {
        if (buffer) vk.DestroyBuffer(device, buffer, nullptr);
        if (memory) vk.FreeMemory(device, memory, nullptr);
        throw;
    }
    ptp_table_buffer = buffer;
    ptp_table_memory = memory;
    return {ptp_table_buffer, 0, bytes};
}

}  // namespace patchcull::vk
