// The Vulkan tests' context: one vk::HeadlessDevice per test process (vk_device.h: Mesa's
// lavapipe, the CPU device, with VK_LAYER_KHRONOS_validation and its synchronization validation
// on, keeping every warning and error the layers and the loader report). VkTest, the fixture of
// the Vulkan tests, fails a test that leaves any message.
#pragma once

#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/vk/vk_device.h"
#include "patchcull/vk/vk_passes.h"

namespace patchcull::vk::test {

class Context {
public:
    /// The process's context (made on first use). Failing to make it (no lavapipe, no validation
    /// layer) throws: a test failure, not a skip.
    static Context& get();
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    VkInstance instance() const { return device_.instance(); }
    VkPhysicalDevice physical_device() const { return device_.physical_device(); }
    VkDevice device() const { return device_.device(); }
    /// The process's PassContext on device() (exact fma).
    PassContext& passes();

    /// Records record(cmd) into a fresh primary command buffer, then a barrier to host reads,
    /// submits it and waits for it.
    void submit(const std::function<void(VkCommandBuffer)>& record);

    /// The messages reported since the last call (and forgets them); with
    /// PATCHCULL_VK_TEST_PRINT set, each is also printed on stderr.
    std::vector<std::string> take_messages();

private:
    Context();
    HeadlessDevice device_;  // vk_device.h: lavapipe, validation and synchronization validation on
    std::unique_ptr<PassContext> passes_;
};

/// A storage buffer in host-visible, coherent memory, mapped for its lifetime.
class HostBuffer {
public:
    explicit HostBuffer(std::size_t bytes);
    ~HostBuffer();
    HostBuffer(const HostBuffer&) = delete;
    HostBuffer& operator=(const HostBuffer&) = delete;
    /// The whole buffer as a range.
    BufferRange range() const { return {buffer_, 0, bytes_}; }
    void write(const void* data, std::size_t bytes, std::size_t offset = 0);
    template <class T>
    std::vector<T> read(std::size_t count, std::size_t offset = 0) const {
        std::vector<T> out(count);
        std::memcpy(out.data(), static_cast<const char*>(mapped_) + offset, count * sizeof(T));
        return out;
    }

private:
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    void* mapped_ = nullptr;
    VkDeviceSize bytes_ = 0;
};

/// The fixture of the Vulkan tests: the context exists before the test, and the test fails when
/// the layers reported anything during it.
class VkTest : public ::testing::Test {
protected:
    void SetUp() override { Context::get().take_messages(); }
    void TearDown() override {
        const std::vector<std::string> messages = Context::get().take_messages();
        EXPECT_TRUE(messages.empty()) << messages.size() << " validation message(s), the first: " << messages.front();
    }
    Context& vk() { return Context::get(); }
};

}  // namespace patchcull::vk::test
