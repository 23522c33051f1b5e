// The headless renderer's graphics pipelines (vk_renderer.h), not a public header: the patch
// draws (shaders/patch.*.glsl) and the occluder draws (occluder.*.glsl) for dynamic rendering
// into RGBA8 colour, R32_UINT id and D32_SFLOAT depth, with push descriptors at shared.h's
// bindings and shaders/draw_params.h's push-constant block (DrawPushConstants).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <map>
#include <string>

#include "patchcull/vk/vk_device.h"

namespace patchcull::vk::detail {

/// shaders/draw_params.h's DrawParams block (std140), byte for byte.
struct DrawPushConstants {
    float object_to_clip[16];
    float eye[3];
    float tess_level;
    std::uint32_t draw_mask, draw_value, adaptive;
    float tess_reference;
    std::uint32_t mark_drawn, has_tangents;
    float displacement_scale, displacement_midlevel;
    std::uint32_t color_mode, discard_back_facing, displace, has_margins;
};
static_assert(sizeof(DrawPushConstants) == 128, "draw_params.h's block is 128 bytes");

/// What a pipeline draws.
enum class DrawKind {
    patches,              ///< patch.*.glsl: every issued patch, the TCS's selection
    patch_list,           ///< the same with PATCHCULL_DRAW_LIST: a compacted list
    mark_front,           ///< PATCHCULL_MARK_FRONT: depth EQUAL, no writes, front marks
    occluders,            ///< occluder.*.glsl, two-sided
    occluders_one_sided,  ///< the same, back faces culled (counter-clockwise front)
};

class DrawPipelines {
public:
    explicit DrawPipelines(HeadlessDevice& device);
    ~DrawPipelines();
    DrawPipelines(const DrawPipelines&) = delete;
    DrawPipelines& operator=(const DrawPipelines&) = delete;

    /// The pipeline of kind with the depth test of the convention (LESS, or GREATER when
    /// reversed; mark_front: EQUAL), made on first use.
    VkPipeline get(DrawKind kind, bool reversed);
    VkPipelineLayout patch_layout() const { return patch_layout_; }
    VkPipelineLayout occluder_layout() const { return occluder_layout_; }
    PFN_vkCmdPushDescriptorSetKHR push_descriptors() const { return push_descriptors_; }

private:
    void create_layouts();  ///< the set and pipeline layouts, the push-descriptor command
    void release();         ///< destroys what exists
    VkShaderModule module(const char* shader, const char* variant);
    HeadlessDevice* device_;
    VkDescriptorSetLayout patch_set_ = VK_NULL_HANDLE, occluder_set_ = VK_NULL_HANDLE;
    VkPipelineLayout patch_layout_ = VK_NULL_HANDLE, occluder_layout_ = VK_NULL_HANDLE;
    PFN_vkCmdPushDescriptorSetKHR push_descriptors_ = nullptr;
    std::map<int, VkPipeline> pipelines_;  // key: kind * 2 + reversed
    std::map<std::string, VkShaderModule> modules_;
};

}  // namespace patchcull::vk::detail
