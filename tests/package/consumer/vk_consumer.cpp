// Uses patchcull::vk from an installed package: a Vulkan instance and a device on the first
// physical device (Mesa lavapipe without a GPU) with VK_KHR_push_descriptor, and a
// vk::PassContext on them, as an engine brings its own. Exit status 1 on any failure.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "check.h"
#include "patchcull/vk/vk_passes.h"

namespace pc = patchcull;

namespace {

void vk_check(VkResult r, const char* what) {
    if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed: VkResult " + std::to_string(r));
}

}  // namespace

int main() {
    VkInstance instance = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    try {
        VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
        app.apiVersion = VK_API_VERSION_1_1;
        VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
        ici.pApplicationInfo = &app;
        vk_check(vkCreateInstance(&ici, nullptr, &instance), "vkCreateInstance");
        std::uint32_t n = 0;
        vkEnumeratePhysicalDevices(instance, &n, nullptr);
        std::vector<VkPhysicalDevice> devices(n);
        vkEnumeratePhysicalDevices(instance, &n, devices.data());
        check(n > 0, std::to_string(n) + " physical device(s)");
        if (n == 0) return 1;
        VkPhysicalDevice physical = devices[0];
        VkPhysicalDeviceFeatures features{};
        vkGetPhysicalDeviceFeatures(physical, &features);
        VkPhysicalDeviceFeatures enabled{};
        enabled.shaderFloat64 = features.shaderFloat64;
        const float priority = 1.0f;
        VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        qci.queueFamilyIndex = 0;
        qci.queueCount = 1;
        qci.pQueuePriorities = &priority;
        const char* extensions[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
        VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        dci.queueCreateInfoCount = 1;
        dci.pQueueCreateInfos = &qci;
        dci.enabledExtensionCount = 1;
        dci.ppEnabledExtensionNames = extensions;
        dci.pEnabledFeatures = &enabled;
        vk_check(vkCreateDevice(physical, &dci, nullptr, &device), "vkCreateDevice");
        {
            pc::vk::PassContextOptions options;
            if (!features.shaderFloat64) options.fma = pc::vk::PassContextOptions::Fma::hardware;
            pc::vk::PassContext passes(physical, device, options);
            check(true, std::string("vk::PassContext on the device (exact fma: ") +
                            (passes.fma_via_double() ? "yes" : "no") + ")");
        }
    } catch (const std::exception& e) {
        check(false, std::string("vk: ") + e.what());
    }
    if (device) vkDestroyDevice(device, nullptr);
    if (instance) vkDestroyInstance(instance, nullptr);
    return failures == 0 ? 0 : 1;
}
