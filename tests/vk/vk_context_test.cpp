// The Vulkan tests' own context (vk_test_util.h): lavapipe with the validation layers, and a
// messenger that does catch what the layers report (so VkTest's "no message" means something).
#include <gtest/gtest.h>

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
