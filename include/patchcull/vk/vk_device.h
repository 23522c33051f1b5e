// patchcull/vk/vk_device.h: a headless Vulkan instance and device of patchcull's own (library
// patchcull_vk), for its tessellation renderer (vk_renderer.h), the CLI's `--api vulkan` and the
// tests. An engine does not need it: the passes (vk_passes.h) run on the engine's own device.
//
// The device: the first physical device with Vulkan 1.3 and a queue for graphics and compute, of
// the kind HeadlessDeviceOptions::prefer asks for when there is one (a CPU device by default:
// lavapipe, Mesa's CPU driver, so that runs are alike everywhere; a GPU for measurements), created with what the passes
// and the renderer need: VK_KHR_push_descriptor, shaderFloat64 (the passes' exact fma), tessellationShader,
// multiDrawIndirect, vertexPipelineStoresAndAtomics and fragmentStoresAndAtomics (the drawn and front marks),
// drawIndirectCount and dynamicRendering, and linear filtering of R32_SFLOAT images (the
// displacement map). A device that lacks one is passed over; when none has everything: Error
// naming what the first device lacks.
//
// Validation (HeadlessDeviceOptions::validation): VK_LAYER_KHRONOS_validation with synchronization
// validation, and a messenger that keeps every warning and error of the validation and general
// types (performance advice is not asked for: the renderer keeps its images in GENERAL layout);
// take_messages() hands them over. Threads: one at a time. Errors: patchcull::Error, one line
// starting with "Vulkan: ".
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/core/thread_placement.h"

namespace patchcull::vk {

struct HeadlessDeviceOptions {
    /// Turn on the Khronos validation layer (Error when it is not installed: Debian's
    /// vulkan-validationlayers).
    bool validation = false;
    /// The kind of physical device tried first (any other with what is needed after it).
    enum class Prefer { cpu, gpu };
    Prefer prefer = Prefer::cpu;
    /// The threads started while the device is made (the driver's workers, and any other thread
    /// the process starts meanwhile): on a CPU device, each pinned to a CPU of its own in turn
    /// (core/thread_placement.h), or left to the operating system.
    DriverThreads driver_threads = DriverThreads::spread;
};

class HeadlessDevice {
public:
    explicit HeadlessDevice(const HeadlessDeviceOptions& options = {});
    ~HeadlessDevice();
    HeadlessDevice(const HeadlessDevice&) = delete;
    HeadlessDevice& operator=(const HeadlessDevice&) = delete;

    VkInstance instance() const { return instance_; }
    VkPhysicalDevice physical_device() const { return physical_device_; }
    VkDevice device() const { return device_; }
    VkQueue queue() const { return queue_; }
    std::uint32_t queue_family() const { return queue_family_; }
    /// The physical device's name (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
    const std::string& name() const { return name_; }
    /// True for a CPU device (lavapipe).
    bool is_software() const { return software_; }
    /// How many driver threads the device pinned (DriverThreads::spread on a CPU device with two
    /// CPUs or more); 0 otherwise.
    std::size_t pinned_driver_threads() const { return pinned_driver_threads_; }
    /// Nanoseconds per timestamp tick (VkPhysicalDeviceLimits::timestampPeriod); 0 when the queue
    /// has no timestamps.
    double timestamp_period_ns() const { return timestamp_period_ns_; }
    bool validation() const { return messenger_ != VK_NULL_HANDLE; }

    /// Records record(cmd) into a fresh primary command buffer, then a barrier making every write
    /// visible to the host, submits it and waits.
    void submit(const std::function<void(VkCommandBuffer)>& record);
    /// The validation and loader messages since the last call (and forgets them).
    std::vector<std::string> take_messages();
    /// Adds a message (the messenger's callback).
    void report(std::string message) { messages_.push_back(std::move(message)); }

    /// A memory type index of memory_type_bits with all of the flags wanted, or Error.
    std::uint32_t memory_type(std::uint32_t memory_type_bits, VkMemoryPropertyFlags wanted) const;

private:
    void release();  ///< destroys what exists, in reverse order
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    std::uint32_t queue_family_ = 0;
    std::size_t pinned_driver_threads_ = 0;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    std::string name_;
    bool software_ = false;
    double timestamp_period_ns_ = 0;
    std::vector<std::string> messages_;
};

}  // namespace patchcull::vk
