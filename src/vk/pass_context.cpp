// PassContext of the Vulkan passes (patchcull/vk/vk_passes.h): device commands, the pipeline
// cache, the placeholder buffer, the range checks and the recording shared by every pass.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "spirv_modules.h"
#include "vk_common.h"

namespace patchcull::vk {

// The C++ parameter structs are the std140 push-constant blocks (shaders/api.h, pass_params.h).
static_assert(sizeof(pp::FrustumParams) == 128);
static_assert(sizeof(pp::CullStatusParams) == 16);
static_assert(sizeof(pp::FrustumDispParams) == 96);
static_assert(sizeof(pp::BackpatchConeParams) == 48);
static_assert(sizeof(pp::BackpatchPtpParams) == 80);
static_assert(sizeof(pp::OcclusionParams) == 144);

namespace detail {

void check_vk(VkResult result, const char* who, const char* what) {
    if (result == VK_SUCCESS) return;
    throw Error(std::string("Vulkan: ") + who + ": " + what + " failed (VkResult " +
                std::to_string(static_cast<int>(result)) + ")");
}

}  // namespace detail

using detail::check_vk;

namespace {

template <class F>
void load(PFN_vkGetDeviceProcAddr get, VkDevice device, F& f, const char* name) {
    f = reinterpret_cast<F>(get(device, name));
    if (!f) throw Error(std::string("Vulkan: PassContext: the device has no ") + name);
}

bool has_extension(VkPhysicalDevice physical_device, const char* name) {
    std::uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(physical_device, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vkEnumerateDeviceExtensionProperties(physical_device, nullptr, &count, extensions.data());
    for (const VkExtensionProperties& e : extensions)
        if (std::strcmp(e.extensionName, name) == 0) return true;
    return false;
}

void create_buffer(PassContext::Impl& m, VkDeviceSize size, VkBufferUsageFlags usage, VkBuffer& buffer,
                   VkDeviceMemory& memory) {
    const detail::DeviceCommands& c = m.vk;
    VkBufferCreateInfo buffer_info{};
    buffer_info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    buffer_info.size = size;
    buffer_info.usage = usage;
    buffer_info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check_vk(c.CreateBuffer(m.device, &buffer_info, nullptr, &buffer), "PassContext", "vkCreateBuffer");
    VkMemoryRequirements requirements{};
    c.GetBufferMemoryRequirements(m.device, buffer, &requirements);
    VkPhysicalDeviceMemoryProperties properties{};
    vkGetPhysicalDeviceMemoryProperties(m.physical_device, &properties);
    std::uint32_t type = properties.memoryTypeCount;
    for (std::uint32_t i = 0; i < properties.memoryTypeCount && type == properties.memoryTypeCount; ++i)
        if ((requirements.memoryTypeBits & (1u << i)) &&
            (properties.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT))
            type = i;
    for (std::uint32_t i = 0; i < properties.memoryTypeCount && type == properties.memoryTypeCount; ++i)
        if (requirements.memoryTypeBits & (1u << i)) type = i;
    if (type == properties.memoryTypeCount) throw Error("Vulkan: PassContext: no memory type for its buffers");
    VkMemoryAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = type;
    check_vk(c.AllocateMemory(m.device, &allocate, nullptr, &memory), "PassContext", "vkAllocateMemory");
    check_vk(c.BindBufferMemory(m.device, buffer, memory, 0), "PassContext", "vkBindBufferMemory");
}

}  // namespace

PassContext::PassContext(VkPhysicalDevice physical_device, VkDevice device, const PassContextOptions& options)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.physical_device = physical_device;
    m.device = device;
    m.options = options;
    if (!physical_device || !device) throw Error("Vulkan: PassContext: no physical device or device");
    if (!has_extension(physical_device, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME))
        throw Error("Vulkan: PassContext: the device lacks " VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    VkPhysicalDeviceProperties properties{};
    vkGetPhysicalDeviceProperties(physical_device, &properties);
    m.limits = properties.limits;
    VkPhysicalDeviceFeatures features{};
    vkGetPhysicalDeviceFeatures(physical_device, &features);
    switch (options.fma) {
        case PassContextOptions::Fma::automatic:
            if (!features.shaderFloat64)
                throw Error(
                    "Vulkan: PassContext: no shaderFloat64 for the exact fma (PassContextOptions::fma: "
                    "choose hardware)");
            m.fma_via_double = true;
            break;
        case PassContextOptions::Fma::exact_double:
            m.fma_via_double = true;
            break;
        case PassContextOptions::Fma::hardware:
            m.fma_via_double = false;
            break;
    }
    if (m.fma_via_double && !features.shaderFloat64)
        throw Error("Vulkan: PassContext: the exact fma needs shaderFloat64, which the device lacks");

    const PFN_vkGetDeviceProcAddr get =
        options.get_device_proc_addr ? options.get_device_proc_addr : vkGetDeviceProcAddr;
    detail::DeviceCommands& c = m.vk;
    load(get, device, c.CreateShaderModule, "vkCreateShaderModule");
    load(get, device, c.DestroyShaderModule, "vkDestroyShaderModule");
    load(get, device, c.CreateDescriptorSetLayout, "vkCreateDescriptorSetLayout");
    load(get, device, c.DestroyDescriptorSetLayout, "vkDestroyDescriptorSetLayout");
    load(get, device, c.CreatePipelineLayout, "vkCreatePipelineLayout");
    load(get, device, c.DestroyPipelineLayout, "vkDestroyPipelineLayout");
    load(get, device, c.CreateComputePipelines, "vkCreateComputePipelines");
    load(get, device, c.DestroyPipeline, "vkDestroyPipeline");
    load(get, device, c.CreateBuffer, "vkCreateBuffer");
    load(get, device, c.DestroyBuffer, "vkDestroyBuffer");
    load(get, device, c.GetBufferMemoryRequirements, "vkGetBufferMemoryRequirements");
    load(get, device, c.AllocateMemory, "vkAllocateMemory");
    load(get, device, c.FreeMemory, "vkFreeMemory");
    load(get, device, c.BindBufferMemory, "vkBindBufferMemory");
    load(get, device, c.MapMemory, "vkMapMemory");
    load(get, device, c.UnmapMemory, "vkUnmapMemory");
    load(get, device, c.CmdBindPipeline, "vkCmdBindPipeline");
    load(get, device, c.CmdPushDescriptorSetKHR, "vkCmdPushDescriptorSetKHR");
    load(get, device, c.CmdPushConstants, "vkCmdPushConstants");
    load(get, device, c.CmdDispatch, "vkCmdDispatch");
    load(get, device, c.CmdPipelineBarrier, "vkCmdPipelineBarrier");
    load(get, device, c.CmdUpdateBuffer, "vkCmdUpdateBuffer");
    load(get, device, c.CreateSampler, "vkCreateSampler");
    load(get, device, c.DestroySampler, "vkDestroySampler");

    VkSamplerCreateInfo sampler_info{};
    sampler_info.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    sampler_info.magFilter = VK_FILTER_NEAREST;
    sampler_info.minFilter = VK_FILTER_NEAREST;
    sampler_info.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    sampler_info.addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    sampler_info.addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    sampler_info.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    sampler_info.maxLod = VK_LOD_CLAMP_NONE;
    check_vk(c.CreateSampler(device, &sampler_info, nullptr, &m.sampler), "PassContext", "vkCreateSampler");

    // The placeholder (256 bytes of storage) and the parameter buffer, device-local where a
    // memory type offers it.
    create_buffer(m, 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, m.placeholder, m.placeholder_memory);
    create_buffer(m, Impl::kParamBufferBytes, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                  m.param_buffer, m.param_memory);
}

PassContext::Impl::~Impl() {
    if (!device) return;
    for (auto& [name, p] : pipelines) {
        vk.DestroyPipeline(device, p.pipeline, nullptr);
        vk.DestroyPipelineLayout(device, p.layout, nullptr);
        vk.DestroyDescriptorSetLayout(device, p.set_layout, nullptr);
    }
    if (vk.DestroySampler) vk.DestroySampler(device, sampler, nullptr);
    if (vk.DestroyBuffer) {
        vk.DestroyBuffer(device, placeholder, nullptr);
        vk.DestroyBuffer(device, param_buffer, nullptr);
        vk.DestroyBuffer(device, ptp_table_buffer, nullptr);
    }
    if (vk.FreeMemory) {
        vk.FreeMemory(device, placeholder_memory, nullptr);
        vk.FreeMemory(device, param_memory, nullptr);
        vk.FreeMemory(device, ptp_table_memory, nullptr);
    }
}

PassContext::PassContext(PassContext&&) noexcept = default;
PassContext& PassContext::operator=(PassContext&&) noexcept = default;
PassContext::~PassContext() = default;
bool PassContext::fma_via_double() const { return impl_->fma_via_double; }
PassContext::Impl& PassContext::impl() { return *impl_; }

const detail::Pipeline& PassContext::Impl::pipeline(const char* shader, const char* variant,
                                                    std::initializer_list<detail::Slot> slots,
                                                    std::uint32_t push_constant_bytes) {
    // The key in a buffer on the stack (a run allocates nothing once its pipeline exists).
    char key_text[128];
    const int key_length = std::snprintf(key_text, sizeof key_text, "%s %s", shader, variant);
    if (key_length < 0 || static_cast<std::size_t>(key_length) >= sizeof key_text)
        throw Error(std::string("Vulkan: ") + shader + ": a pipeline key too long");
    const std::string_view key(key_text, static_cast<std::size_t>(key_length));
    auto it = pipelines.find(key);
    if (it != pipelines.end()) return it->second;
    if (push_constant_bytes > limits.maxPushConstantsSize)
        throw Error(std::string("Vulkan: ") + shader + ": its " + std::to_string(push_constant_bytes) +
                    "-byte parameter block exceeds maxPushConstantsSize (" +
                    std::to_string(limits.maxPushConstantsSize) + ")");
    const detail::SpirvModule* module = detail::find_spirv_module(shader, variant, fma_via_double);
    if (!module) throw Error(std::string("Vulkan: ") + shader + " " + variant + " has no SPIR-V module");

    detail::Pipeline p;
    p.push_constant_bytes = push_constant_bytes;
    VkShaderModule shader_module = VK_NULL_HANDLE;
    try {
        std::array<VkDescriptorSetLayoutBinding, detail::kMaxBindings> layout_bindings{};
        std::uint32_t n = 0;
        for (const detail::Slot& slot : slots) {
            layout_bindings[n].binding = slot.binding;
            layout_bindings[n].descriptorType = slot.type;
            layout_bindings[n].descriptorCount = 1;
            layout_bindings[n].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
            ++n;
        }
        VkDescriptorSetLayoutCreateInfo set_info{};
        set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
        set_info.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
        set_info.bindingCount = n;
        set_info.pBindings = layout_bindings.data();
        check_vk(vk.CreateDescriptorSetLayout(device, &set_info, nullptr, &p.set_layout), shader,
                 "vkCreateDescriptorSetLayout");
        VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_constant_bytes};
        VkPipelineLayoutCreateInfo layout_info{};
        layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
        layout_info.setLayoutCount = 1;
        layout_info.pSetLayouts = &p.set_layout;
        layout_info.pushConstantRangeCount = push_constant_bytes ? 1 : 0;
        layout_info.pPushConstantRanges = &range;
        check_vk(vk.CreatePipelineLayout(device, &layout_info, nullptr, &p.layout), shader, "vkCreatePipelineLayout");
        VkShaderModuleCreateInfo module_info{};
        module_info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
        module_info.codeSize = module->word_count * 4;
        module_info.pCode = module->words;
        check_vk(vk.CreateShaderModule(device, &module_info, nullptr, &shader_module), shader, "vkCreateShaderModule");
        VkComputePipelineCreateInfo pipeline_info{};
        pipeline_info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
        pipeline_info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        pipeline_info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        pipeline_info.stage.module = shader_module;
        pipeline_info.stage.pName = "main";
        pipeline_info.layout = p.layout;
        check_vk(vk.CreateComputePipelines(device, options.pipeline_cache, 1, &pipeline_info, nullptr, &p.pipeline),
                 shader, "vkCreateComputePipelines");
        vk.DestroyShaderModule(device, shader_module, nullptr);
    } catch (...) {
        if (shader_module) vk.DestroyShaderModule(device, shader_module, nullptr);
        if (p.layout) vk.DestroyPipelineLayout(device, p.layout, nullptr);
        if (p.set_layout) vk.DestroyDescriptorSetLayout(device, p.set_layout, nullptr);
        throw;
    }
    return pipelines.emplace(std::string(key), p).first->second;
}

void PassContext::Impl::check_range(const char* who, const char* what, const BufferRange& range, VkDeviceSize bytes,
                                    bool optional) const {
    // The message is made only on failure: a run allocates nothing on the host.
    auto prefix = [&] { return std::string("Vulkan: ") + who + ": the " + what + " range "; };
    if (range.buffer == VK_NULL_HANDLE) {
        if (optional && range.size == 0) return;
        throw Error(prefix() + "has no buffer");
    }
    if (range.size == VK_WHOLE_SIZE) throw Error(prefix() + "has size VK_WHOLE_SIZE (give its size)");
    if (range.size < bytes)
        throw Error(prefix() + "holds " + std::to_string(range.size) + " bytes, " + std::to_string(bytes) + " needed");
    if (range.offset % limits.minStorageBufferOffsetAlignment != 0)
        throw Error(prefix() + "starts at " + std::to_string(range.offset) + ", not a multiple of " +
                    std::to_string(limits.minStorageBufferOffsetAlignment) + " (minStorageBufferOffsetAlignment)");
    if (range.size > limits.maxStorageBufferRange)
        throw Error(prefix() + "of " + std::to_string(range.size) + " bytes exceeds maxStorageBufferRange (" +
                    std::to_string(limits.maxStorageBufferRange) + ")");
}

void PassContext::Impl::bind(VkCommandBuffer cmd, const detail::Pipeline& p, const detail::Binding* bindings,
                             std::size_t binding_count, VkDeviceSize param_bytes, VkImageView hiz) const {
    std::array<VkDescriptorBufferInfo, detail::kMaxBindings> infos{};
    std::array<VkWriteDescriptorSet, detail::kMaxBindings> writes{};
    std::size_t n = 0;
    for (; n < binding_count; ++n) {
        const BufferRange& r = bindings[n].range;
        infos[n] = r.buffer ? VkDescriptorBufferInfo{r.buffer, r.offset, r.size}
                            : VkDescriptorBufferInfo{placeholder, 0, VK_WHOLE_SIZE};
        writes[n].dstBinding = bindings[n].binding;
        writes[n].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[n].pBufferInfo = &infos[n];
    }
    if (param_bytes > 0) {
        infos[n] = {param_buffer, 0, param_bytes};
        writes[n].dstBinding = api::kParamsBinding;
        writes[n].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
        writes[n].pBufferInfo = &infos[n];
        ++n;
    }
    const VkDescriptorImageInfo image{sampler, hiz, VK_IMAGE_LAYOUT_GENERAL};
    if (hiz != VK_NULL_HANDLE) {
        writes[n].dstBinding = api::kTextureHiZBinding;
        writes[n].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        writes[n].pImageInfo = &image;
        ++n;
    }
    for (std::size_t i = 0; i < n; ++i) {
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].descriptorCount = 1;
    }
    vk.CmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vk.CmdPushDescriptorSetKHR(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, static_cast<std::uint32_t>(n),
                               writes.data());
}

void PassContext::Impl::update_params(VkCommandBuffer cmd, const void* data, std::size_t bytes) const {
    vk.CmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                          nullptr, 0, nullptr);
    vk.CmdUpdateBuffer(cmd, param_buffer, 0, bytes, data);
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_UNIFORM_READ_BIT;
    vk.CmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier, 0,
                          nullptr, 0, nullptr);
}

void PassContext::Impl::barrier_after(VkCommandBuffer cmd) const {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = options.after_access;
    vk.CmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, options.after_stages, 0, 1, &barrier, 0, nullptr,
                          0, nullptr);
}

}  // namespace patchcull::vk
