// HeadlessDevice (patchcull/vk/vk_device.h): patchcull's own instance and device.
#include <cstring>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/vk/vk_device.h"

namespace patchcull::vk {

namespace {

void check(VkResult result, const char* what) {
    if (result != VK_SUCCESS)
        throw Error(std::string("Vulkan: HeadlessDevice: ") + what + " failed (VkResult " +
                    std::to_string(static_cast<int>(result)) + ")");
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT type,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    (void)type;
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT)
        static_cast<HeadlessDevice*>(user)->report(data->pMessage ? data->pMessage : "(no text)");
    return VK_FALSE;
}

bool has_layer(const char* name) {
    std::uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    for (const VkLayerProperties& l : layers)
        if (std::strcmp(l.layerName, name) == 0) return true;
    return false;
}

// The queue family with graphics and compute, or the family count when there is none.
std::uint32_t graphics_family(VkPhysicalDevice device) {
    std::uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
    for (std::uint32_t i = 0; i < count; ++i)
        if ((families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) && (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT))
            return i;
    return count;
}

// What the renderer needs that device lacks (its first missing item), or "" when it has everything:
// Vulkan 1.3, a graphics and compute queue, VK_KHR_push_descriptor, the features of the header and
// linear filtering of R32_SFLOAT (the displacement map).
std::string missing_requirement(VkPhysicalDevice device) {
    VkPhysicalDeviceProperties p{};
    vkGetPhysicalDeviceProperties(device, &p);
    if (p.apiVersion < VK_API_VERSION_1_3) return "Vulkan 1.3";
    std::uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &families, nullptr);
    if (graphics_family(device) == families) return "a queue for graphics and compute";
    std::uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
    bool push_descriptor = false;
    for (const VkExtensionProperties& e : extensions)
        push_descriptor = push_descriptor || std::strcmp(e.extensionName, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME) == 0;
    if (!push_descriptor) return VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME;
    VkPhysicalDeviceVulkan13Features have13{};
    have13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    VkPhysicalDeviceVulkan12Features have12{};
    have12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    have12.pNext = &have13;
    VkPhysicalDeviceFeatures2 have{};
    have.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    have.pNext = &have12;
    vkGetPhysicalDeviceFeatures2(device, &have);
    const std::pair<VkBool32, const char*> needed[] = {
        {have.features.shaderFloat64, "the feature shaderFloat64"},
        {have.features.tessellationShader, "the feature tessellationShader"},
        {have.features.multiDrawIndirect, "the feature multiDrawIndirect"},
        {have.features.vertexPipelineStoresAndAtomics, "the feature vertexPipelineStoresAndAtomics"},
        {have.features.fragmentStoresAndAtomics, "the feature fragmentStoresAndAtomics"},
        {have12.drawIndirectCount, "the feature drawIndirectCount"},
        {have13.dynamicRendering, "the feature dynamicRendering"}};
    for (const auto& [supported, what] : needed)
        if (!supported) return what;
    VkFormatProperties format{};
    vkGetPhysicalDeviceFormatProperties(device, VK_FORMAT_R32_SFLOAT, &format);
    if (!(format.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT))
        return "linear filtering of R32_SFLOAT images";
    return "";
}

}  // namespace

HeadlessDevice::HeadlessDevice(const HeadlessDeviceOptions& options) {
    const std::vector<int> threads_before = process_thread_ids();
    const char* layer = "VK_LAYER_KHRONOS_validation";
    if (options.validation && !has_layer(layer))
        throw Error("Vulkan: no VK_LAYER_KHRONOS_validation for validation (Debian: vulkan-validationlayers)");
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "patchcull";
    app.apiVersion = VK_API_VERSION_1_3;
    VkDebugUtilsMessengerCreateInfoEXT messenger{};
    messenger.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    messenger.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    // Not performance advice: the renderer keeps its images in GENERAL layout on purpose.
    messenger.messageType =
        VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    messenger.pfnUserCallback = on_message;
    messenger.pUserData = this;
    const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    VkValidationFeaturesEXT features{};
    features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    features.pNext = &messenger;
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = enables;
    const char* extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
    VkInstanceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    info.pApplicationInfo = &app;
    if (options.validation) {
        info.pNext = &features;
        info.enabledLayerCount = 1;
        info.ppEnabledLayerNames = &layer;
        info.enabledExtensionCount = 1;
        info.ppEnabledExtensionNames = extensions;
    }
    check(vkCreateInstance(&info, nullptr, &instance_), "vkCreateInstance (is a Vulkan driver installed?)");
    try {
        if (options.validation) {
            auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
            if (!create) throw Error("Vulkan: HeadlessDevice: no vkCreateDebugUtilsMessengerEXT");
            check(create(instance_, &messenger, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
        }
        std::uint32_t count = 0;
        vkEnumeratePhysicalDevices(instance_, &count, nullptr);
        std::vector<VkPhysicalDevice> devices(count);
        vkEnumeratePhysicalDevices(instance_, &count, devices.data());
        for (int pass = 0; pass < 2 && !physical_device_; ++pass)
            for (VkPhysicalDevice d : devices) {
                VkPhysicalDeviceProperties p{};
                vkGetPhysicalDeviceProperties(d, &p);
                const bool cpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
                const bool gpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU ||
                                 p.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU;
                const bool preferred = options.prefer == HeadlessDeviceOptions::Prefer::cpu ? cpu : gpu;
                if ((pass == 0 && !preferred) || !missing_requirement(d).empty()) continue;
                physical_device_ = d;
                name_ = p.deviceName;
                software_ = cpu;
                timestamp_period_ns_ = p.limits.timestampPeriod;
                break;
            }
        if (!physical_device_) {
            if (devices.empty()) throw Error("Vulkan: no device (Debian: mesa-vulkan-drivers)");
            VkPhysicalDeviceProperties p{};
            vkGetPhysicalDeviceProperties(devices[0], &p);
            throw Error(std::string("Vulkan: no device has what the renderer needs (") + p.deviceName + " lacks " +
                        missing_requirement(devices[0]) + ")");
        }
        queue_family_ = graphics_family(physical_device_);
        {
            std::uint32_t families = 0;
            vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &families, nullptr);
            std::vector<VkQueueFamilyProperties> props(families);
            vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &families, props.data());
            if (props[queue_family_].timestampValidBits == 0) timestamp_period_ns_ = 0;
        }

        VkPhysicalDeviceVulkan13Features enable13{};
        enable13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
        enable13.dynamicRendering = VK_TRUE;
        VkPhysicalDeviceVulkan12Features enable12{};
        enable12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
        enable12.pNext = &enable13;
        enable12.drawIndirectCount = VK_TRUE;
        VkPhysicalDeviceFeatures2 enable{};
        enable.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
        enable.pNext = &enable12;
        enable.features.shaderFloat64 = VK_TRUE;
        enable.features.tessellationShader = VK_TRUE;
        enable.features.multiDrawIndirect = VK_TRUE;
        enable.features.vertexPipelineStoresAndAtomics = VK_TRUE;
        enable.features.fragmentStoresAndAtomics = VK_TRUE;
        const float priority = 1.0f;
        VkDeviceQueueCreateInfo queue{};
        queue.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
        queue.queueFamilyIndex = queue_family_;
        queue.queueCount = 1;
        queue.pQueuePriorities = &priority;
        const char* device_extensions[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
        VkDeviceCreateInfo device_info{};
        device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
        device_info.pNext = &enable;
        device_info.queueCreateInfoCount = 1;
        device_info.pQueueCreateInfos = &queue;
        device_info.enabledExtensionCount = 1;
        device_info.ppEnabledExtensionNames = device_extensions;
        check(vkCreateDevice(physical_device_, &device_info, nullptr, &device_), "vkCreateDevice");
        vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
        VkCommandPoolCreateInfo pool{};
        pool.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
        pool.queueFamilyIndex = queue_family_;
        check(vkCreateCommandPool(device_, &pool, nullptr, &pool_), "vkCreateCommandPool");
        if (options.driver_threads == DriverThreads::spread && software_)
            pinned_driver_threads_ = spread_threads(threads_started(threads_before, process_thread_ids()));
    } catch (...) {
        release();
        throw;
    }
}

HeadlessDevice::~HeadlessDevice() { release(); }

void HeadlessDevice::release() {
    if (device_) vkDeviceWaitIdle(device_);
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    if (device_) vkDestroyDevice(device_, nullptr);
    if (messenger_) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(instance_, messenger_, nullptr);
    }
    if (instance_) vkDestroyInstance(instance_, nullptr);
    pool_ = VK_NULL_HANDLE;
    device_ = VK_NULL_HANDLE;
    messenger_ = VK_NULL_HANDLE;
    instance_ = VK_NULL_HANDLE;
}

void HeadlessDevice::submit(const std::function<void(VkCommandBuffer)>& record) {
    VkCommandBufferAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    allocate.commandPool = pool_;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    check(vkAllocateCommandBuffers(device_, &allocate, &cmd), "vkAllocateCommandBuffers");
    struct FreeGuard {
        VkDevice device;
        VkCommandPool pool;
        VkCommandBuffer cmd;
        ~FreeGuard() { vkFreeCommandBuffers(device, pool, 1, &cmd); }
    } free_guard{device_, pool_, cmd};
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    try {
        record(cmd);
    } catch (...) {
        vkEndCommandBuffer(cmd);
        throw;
    }
    VkMemoryBarrier to_host{};
    to_host.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    to_host.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                         nullptr, 0, nullptr);
    check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    VkFenceCreateInfo fence_info{};
    fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VkFence fence = VK_NULL_HANDLE;
    check(vkCreateFence(device_, &fence_info, nullptr, &fence), "vkCreateFence");
    VkSubmitInfo submit_info{};
    submit_info.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit_info.commandBufferCount = 1;
    submit_info.pCommandBuffers = &cmd;
    VkResult r = vkQueueSubmit(queue_, 1, &submit_info, fence);
    if (r == VK_SUCCESS) {
        r = vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX);
        // The command buffer must not be pending when the guard frees it.
        if (r != VK_SUCCESS) vkDeviceWaitIdle(device_);
    }
    vkDestroyFence(device_, fence, nullptr);
    check(r, "vkQueueSubmit");
}

std::vector<std::string> HeadlessDevice::take_messages() {
    std::vector<std::string> out;
    out.swap(messages_);
    return out;
}

std::uint32_t HeadlessDevice::memory_type(std::uint32_t memory_type_bits, VkMemoryPropertyFlags wanted) const {
    VkPhysicalDeviceMemoryProperties memory{};
    vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory);
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
        if ((memory_type_bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
    throw Error("Vulkan: HeadlessDevice: no memory type with the properties asked for");
}

}  // namespace patchcull::vk
