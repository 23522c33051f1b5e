// What the Vulkan passes (patchcull/vk/vk_passes.h) share, not a public header: the device
// commands, the pipeline cache of the PassContext, the range checks, and the one way a pass is
// recorded (bind, push descriptors, push constants and dispatches, the barrier after).
#pragma once

#include <vulkan/vulkan.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <map>
#include <string>

#include "api.h"
#include "pass_params.h"
#include "patchcull/core/error.h"
#include "patchcull/vk/vk_passes.h"
#include "shared.h"

namespace patchcull::vk {

namespace pp = gl::pass_params;
namespace shared = gl::shared;

namespace detail {

/// "Vulkan: <who>: <what> failed (VkResult <code>)" unless result is VK_SUCCESS.
void check_vk(VkResult result, const char* who, const char* what);

/// The device commands the passes use, fetched once through vkGetDeviceProcAddr.
struct DeviceCommands {
    PFN_vkCreateShaderModule CreateShaderModule = nullptr;
    PFN_vkDestroyShaderModule DestroyShaderModule = nullptr;
    PFN_vkCreateDescriptorSetLayout CreateDescriptorSetLayout = nullptr;
    PFN_vkDestroyDescriptorSetLayout DestroyDescriptorSetLayout = nullptr;
    PFN_vkCreatePipelineLayout CreatePipelineLayout = nullptr;
    PFN_vkDestroyPipelineLayout DestroyPipelineLayout = nullptr;
    PFN_vkCreateComputePipelines CreateComputePipelines = nullptr;
    PFN_vkDestroyPipeline DestroyPipeline = nullptr;
    PFN_vkCreateBuffer CreateBuffer = nullptr;
    PFN_vkDestroyBuffer DestroyBuffer = nullptr;
    PFN_vkGetBufferMemoryRequirements GetBufferMemoryRequirements = nullptr;
    PFN_vkAllocateMemory AllocateMemory = nullptr;
    PFN_vkFreeMemory FreeMemory = nullptr;
    PFN_vkBindBufferMemory BindBufferMemory = nullptr;
    PFN_vkMapMemory MapMemory = nullptr;
    PFN_vkUnmapMemory UnmapMemory = nullptr;
    PFN_vkCmdBindPipeline CmdBindPipeline = nullptr;
    PFN_vkCmdPushDescriptorSetKHR CmdPushDescriptorSetKHR = nullptr;
    PFN_vkCmdPushConstants CmdPushConstants = nullptr;
    PFN_vkCmdDispatch CmdDispatch = nullptr;
    PFN_vkCmdPipelineBarrier CmdPipelineBarrier = nullptr;
    PFN_vkCmdUpdateBuffer CmdUpdateBuffer = nullptr;
    PFN_vkCreateSampler CreateSampler = nullptr;
    PFN_vkDestroySampler DestroySampler = nullptr;
};

/// One cached compute pipeline: its push-descriptor set layout (storage buffers at `bindings`),
/// its pipeline layout (that set and the push-constant range) and the pipeline.
struct Pipeline {
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    std::uint32_t push_constant_bytes = 0;
};

/// A storage-buffer descriptor of a pass: binding number and range (empty: the context's
/// placeholder buffer).
struct Binding {
    std::uint32_t binding;
    BufferRange range;
};

/// A descriptor of a pipeline's set 0: its binding number and type (a storage buffer unless said).
struct Slot {
    Slot(std::uint32_t b, VkDescriptorType t = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER) : binding(b), type(t) {}
    std::uint32_t binding;
    VkDescriptorType type;
};

/// The most descriptors one pass binds.
inline constexpr std::size_t kMaxBindings = 8;

/// FrustumPlanes into a parameter block's clip_rows, plane_normal_length (packed, pass_params.h)
/// and plane_depth, as the GL passes store them (src/gl/pass_common.cpp's store_planes).
template <class Params>
void store_planes(const FrustumPlanes& planes, Params& params) {
    params.plane_depth = {planes.near_w, planes.far_w, planes.far_limit, 0.0f};
    for (int r = 0; r < 4; ++r)
        params.clip_rows[r] = {planes.clip_rows[r].x, planes.clip_rows[r].y, planes.clip_rows[r].z,
                               planes.clip_rows[r].w};
    float nl[8] = {};
    for (int q = 0; q < 6; ++q) nl[q] = planes.normal_length[q];
    params.plane_normal_length[0] = {nl[0], nl[1], nl[2], nl[3]};
    params.plane_normal_length[1] = {nl[4], nl[5], nl[6], nl[7]};
}

}  // namespace detail

struct PassContext::Impl {
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    PassContextOptions options;
    detail::DeviceCommands vk;
    bool fma_via_double = false;
    VkPhysicalDeviceLimits limits{};
    VkBuffer placeholder = VK_NULL_HANDLE;  // 256 bytes, bound for an empty optional range
    VkDeviceMemory placeholder_memory = VK_NULL_HANDLE;
    VkSampler sampler = VK_NULL_HANDLE;  // nearest, clamp to edge: the Hi-Z passes' texelFetch
    // The parameter block of the passes whose block exceeds 128 bytes (shaders/api.h's
    // PC_VK_UNIFORM_*): kParamBufferBytes of uniform buffer, written by vkCmdUpdateBuffer.
    static constexpr VkDeviceSize kParamBufferBytes = 512;
    VkBuffer param_buffer = VK_NULL_HANDLE;
    VkDeviceMemory param_memory = VK_NULL_HANDLE;
    std::map<std::string, detail::Pipeline, std::less<>> pipelines;  // key: shader name + " " + variant
    // The ptp schedule's tables (shaders/ptp_tables.h) in host-visible memory, written once by
    // ptp_tables() (src/vk/ptp_tables.cpp); made on first use.
    VkBuffer ptp_table_buffer = VK_NULL_HANDLE;
    VkDeviceMemory ptp_table_memory = VK_NULL_HANDLE;

    ~Impl();
    /// The range of the ptp tables' buffer (kBindingPtpTables), created and filled on first call.
    BufferRange ptp_tables();
    /// The pipeline of compute shader `shader` in `variant` ("" or the define of a variant; its
    /// SPIR-V module in this context's fma mode) reading the descriptors `slots` of set 0 and push
    /// constants of push_constant_bytes; created on first use. Throws Error when the block
    /// exceeds maxPushConstantsSize.
    const detail::Pipeline& pipeline(const char* shader, const char* variant, std::initializer_list<detail::Slot> slots,
                                     std::uint32_t push_constant_bytes);
    /// Throws (one line naming who and what) unless range is in a buffer, holds at least bytes
    /// bytes, starts at a multiple of minStorageBufferOffsetAlignment and fits maxStorageBufferRange.
    /// An optional range may be empty (buffer VK_NULL_HANDLE, size 0).
    void check_range(const char* who, const char* what, const BufferRange& range, VkDeviceSize bytes,
                     bool optional) const;
    /// Records a pass: binds p, pushes the descriptors, then per dispatch of at most 65535 work
    /// groups (patches_per_group patches each) sets params.first_patch and params.patch_count,
    /// pushes params and dispatches; then the barrier of the header.
    template <class Params>
    void record(VkCommandBuffer cmd, const detail::Pipeline& p, const detail::Binding* bindings,
                std::size_t binding_count, Params& params, std::size_t first, std::size_t count,
                std::size_t patches_per_group) const {
        bind(cmd, p, bindings, binding_count);
        const std::size_t per_dispatch = 65535 * patches_per_group;
        for (std::size_t offset = 0; offset < count; offset += per_dispatch) {
            const std::size_t n = std::min(per_dispatch, count - offset);
            params.first_patch = static_cast<pp::uint>(first + offset);
            params.patch_count = static_cast<pp::uint>(n);
            vk.CmdPushConstants(cmd, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(Params), &params);
            vk.CmdDispatch(cmd, static_cast<std::uint32_t>((n + patches_per_group - 1) / patches_per_group), 1, 1);
        }
        barrier_after(cmd);
    }
    /// Records a pass whose block lives in the parameter buffer (PC_VK_UNIFORM_*) and which reads
    /// the Hi-Z pyramid view hiz: as record, with the parameter buffer and hiz bound after the
    /// storage buffers and params written by update_params before each dispatch.
    template <class Params>
    void record_uniform(VkCommandBuffer cmd, const detail::Pipeline& p, const detail::Binding* bindings,
                        std::size_t binding_count, VkImageView hiz, Params& params, std::size_t first,
                        std::size_t count, std::size_t patches_per_group) const {
        bind(cmd, p, bindings, binding_count, sizeof(Params), hiz);
        const std::size_t per_dispatch = 65535 * patches_per_group;
        for (std::size_t offset = 0; offset < count; offset += per_dispatch) {
            const std::size_t n = std::min(per_dispatch, count - offset);
            params.first_patch = static_cast<pp::uint>(first + offset);
            params.patch_count = static_cast<pp::uint>(n);
            update_params(cmd, &params, sizeof(Params));
            vk.CmdDispatch(cmd, static_cast<std::uint32_t>((n + patches_per_group - 1) / patches_per_group), 1, 1);
        }
        barrier_after(cmd);
    }
    /// Binds p and pushes the storage-buffer descriptors; with param_bytes > 0 also the parameter
    /// buffer's first param_bytes at api::kParamsBinding, and with hiz the pyramid view and the
    /// context's sampler at api::kTextureHiZBinding.
    void bind(VkCommandBuffer cmd, const detail::Pipeline& p, const detail::Binding* bindings,
              std::size_t binding_count, VkDeviceSize param_bytes = 0, VkImageView hiz = VK_NULL_HANDLE) const;
    void barrier_after(VkCommandBuffer cmd) const;
    /// Records the update of the parameter buffer with bytes (a multiple of 4, at most
    /// kParamBufferBytes) between two barriers: the compute shaders recorded before it finish
    /// first (they may read the buffer), and its transfer write is visible to the uniform reads of
    /// the compute shaders after it.
    void update_params(VkCommandBuffer cmd, const void* data, std::size_t bytes) const;
};

}  // namespace patchcull::vk
