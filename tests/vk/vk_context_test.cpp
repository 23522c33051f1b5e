// The Vulkan tests' own context (vk_test_util.h): lavapipe with the validation layers, and a
// messenger that does catch what the layers report (so VkTest's "no message" means something),
// and the placement of the driver's threads.
#include <gtest/gtest.h>
#include <unistd.h>

#include <vector>

#include "core/driver_thread_checks.h"
#include "patchcull/core/thread_placement.h"
#include "vk/vk_test_util.h"

using namespace patchcull::vk;
using namespace patchcull::vk::test;

TEST(VkContext, LavapipeWithValidationThatReportsAnInvalidCall) {
    Context& vk = Context::get();
    VkPhysicalDeviceProperties p{};
    vkGetPhysicalDeviceProperties(vk.physical_device(), &p);
    EXPECT_EQ(p.deviceType, VK_PHYSICAL_DEVICE_TYPE_CPU);
    EXPECT_TRUE(vk.passes().fma_via_double());
    vk.take_messages();
    // A buffer with no usage bits is invalid (VkBufferCreateInfo's usage must not be 0): the
    // layer reports it, and lavapipe still makes the buffer.
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = 64;
    info.usage = 0;
    VkBuffer buffer = VK_NULL_HANDLE;
    if (vkCreateBuffer(vk.device(), &info, nullptr, &buffer) == VK_SUCCESS)
        vkDestroyBuffer(vk.device(), buffer, nullptr);
    const std::vector<std::string> messages = vk.take_messages();
    ASSERT_FALSE(messages.empty());
    EXPECT_NE(messages.front().find("usage"), std::string::npos) << messages.front();
}

// DriverThreads: on lavapipe the threads the driver starts for a device are pinned one CPU each
// (spread, the default), or left alone (os); the calling thread keeps its CPUs either way.
TEST(VkContext, SpreadsTheDriversThreadsOnACpuDevice) {
    const int me = static_cast<int>(gettid());
    const int cpus = patchcull::thread_cpu_count(me);
    if (cpus < 2) GTEST_SKIP() << "one CPU: nothing to spread";
    for (patchcull::DriverThreads mode : {patchcull::DriverThreads::os, patchcull::DriverThreads::spread}) {
        const std::vector<int> before = patchcull::process_thread_ids();
        HeadlessDeviceOptions options;
        options.driver_threads = mode;
        HeadlessDevice device(options);
        ASSERT_TRUE(device.is_software()) << device.name();
        const std::vector<int> started = patchcull::threads_started(before, patchcull::process_thread_ids());
        const bool spread = mode == patchcull::DriverThreads::spread;
        patchcull::placement_test::expect_driver_threads_placed(started, device.pinned_driver_threads(), spread, cpus);
        EXPECT_EQ(patchcull::thread_cpu_count(me), cpus);
        device.submit([](VkCommandBuffer) {});  // a pinned device still runs work
    }
}
