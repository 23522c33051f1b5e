// The Vulkan tests' context: one headless instance and device per test process on Mesa's
// lavapipe (the physical device of type CPU), with VK_LAYER_KHRONOS_validation and its
// synchronization validation on, and a debug messenger that keeps every message the layers and
// the loader report at warning or error severity (and every validation message). VkTest, the
// fixture of the Vulkan tests, fails a test that leaves any message.
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

    VkInstance instance() const { return instance_; }
    VkPhysicalDevice physical_device() const { return physical_device_; }
    VkDevice device() const { return device_; }
    /// The process's PassContext on device() (exact fma).
    PassContext& passes();

    /// Records record(cmd) into a fresh primary command buffer, then a barrier to host reads,
    /// submits it and waits for it.
    void submit(const std::function<void(VkCommandBuffer)>& record);

    /// The messages reported since the last call (and forgets them).
    std::vector<std::string> take_messages();
    /// Adds a message (the messenger's callback).
    void report(std::string message) { messages_.push_back(std::move(message)); }

private:
    Context();
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    std::uint32_t queue_family_ = 0;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    std::unique_ptr<PassContext> passes_;
    std::vector<std::string> messages_;
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
