// The headless renderer's graphics pipelines (draw_pipelines.h).
#include "draw_pipelines.h"

#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "renderer_resources.h"
#include "shared.h"
#include "spirv_modules.h"

namespace patchcull::vk::detail {

namespace sh = gl::shared;

namespace {

// Set 0 of the patch draws: shared.h's storage bindings and the displacement map at 31
// (draw_params.h), every stage.
constexpr std::uint32_t kPatchStorageBindings[] = {
    sh::kBindingControlPoints, sh::kBindingCullFlags,  sh::kBindingMaxDisplacement, sh::kBindingPatchTexcoords,
    sh::kBindingPatchTangents, sh::kBindingPatchMarks, sh::kBindingPatchTessScale,  sh::kBindingDrawList};
constexpr std::uint32_t kDisplacementMapBinding = 31;

VkDescriptorSetLayout make_set(VkDevice d, const std::vector<VkDescriptorSetLayoutBinding>& bindings) {
    VkDescriptorSetLayoutCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    info.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    info.bindingCount = static_cast<std::uint32_t>(bindings.size());
    info.pBindings = bindings.data();
    VkDescriptorSetLayout set = VK_NULL_HANDLE;
    check_renderer(vkCreateDescriptorSetLayout(d, &info, nullptr, &set), "vkCreateDescriptorSetLayout");
    return set;
}

VkPipelineLayout make_layout(VkDevice d, VkDescriptorSetLayout set) {
    VkPushConstantRange range{VK_SHADER_STAGE_ALL_GRAPHICS, 0, sizeof(DrawPushConstants)};
    VkPipelineLayoutCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    info.setLayoutCount = 1;
    info.pSetLayouts = &set;
    info.pushConstantRangeCount = 1;
    info.pPushConstantRanges = &range;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    check_renderer(vkCreatePipelineLayout(d, &info, nullptr, &layout), "vkCreatePipelineLayout");
    return layout;
}

}  // namespace

DrawPipelines::DrawPipelines(HeadlessDevice& device) : device_(&device) {
    try {
        create_layouts();
    } catch (...) {
        release();
        throw;
    }
}

void DrawPipelines::create_layouts() {
    const VkDevice d = device_->device();
    std::vector<VkDescriptorSetLayoutBinding> patch_bindings;
    for (std::uint32_t b : kPatchStorageBindings)
        patch_bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_ALL_GRAPHICS, nullptr});
    patch_bindings.push_back(
        {kDisplacementMapBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_ALL_GRAPHICS, nullptr});
    patch_set_ = make_set(d, patch_bindings);
    occluder_set_ = make_set(d, {{sh::kBindingOccluderVertices, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1,
                                  VK_SHADER_STAGE_ALL_GRAPHICS, nullptr}});
    patch_layout_ = make_layout(d, patch_set_);
    occluder_layout_ = make_layout(d, occluder_set_);
    push_descriptors_ =
        reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(vkGetDeviceProcAddr(d, "vkCmdPushDescriptorSetKHR"));
    if (!push_descriptors_) throw Error("Vulkan: CullRenderer: the device has no vkCmdPushDescriptorSetKHR");
}

DrawPipelines::~DrawPipelines() { release(); }

void DrawPipelines::release() {
    const VkDevice d = device_->device();
    for (const auto& [key, p] : pipelines_)
        if (p) vkDestroyPipeline(d, p, nullptr);
    for (const auto& [name, m] : modules_)
        if (m) vkDestroyShaderModule(d, m, nullptr);
    pipelines_.clear();
    modules_.clear();
    if (patch_layout_) vkDestroyPipelineLayout(d, patch_layout_, nullptr);
    if (occluder_layout_) vkDestroyPipelineLayout(d, occluder_layout_, nullptr);
    if (patch_set_) vkDestroyDescriptorSetLayout(d, patch_set_, nullptr);
    if (occluder_set_) vkDestroyDescriptorSetLayout(d, occluder_set_, nullptr);
    patch_layout_ = occluder_layout_ = VK_NULL_HANDLE;
    patch_set_ = occluder_set_ = VK_NULL_HANDLE;
}

VkShaderModule DrawPipelines::module(const char* shader, const char* variant) {
    const std::string key = std::string(shader) + " " + variant;
    VkShaderModule& m = modules_[key];
    if (m) return m;
    const SpirvModule* spirv = find_spirv_module(shader, variant, false);
    if (!spirv) throw Error("Vulkan: CullRenderer: no SPIR-V module " + key + " (internal)");
    VkShaderModuleCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    info.codeSize = spirv->word_count * 4;
    info.pCode = spirv->words;
    check_renderer(vkCreateShaderModule(device_->device(), &info, nullptr, &m), "vkCreateShaderModule");
    return m;
}

VkPipeline DrawPipelines::get(DrawKind kind, bool reversed) {
    const int key = static_cast<int>(kind) * 2 + (reversed ? 1 : 0);
    VkPipeline& pipeline = pipelines_[key];
    if (pipeline) return pipeline;
    const bool occluders = kind == DrawKind::occluders || kind == DrawKind::occluders_one_sided;
    std::vector<VkPipelineShaderStageCreateInfo> stages;
    auto stage = [&](VkShaderStageFlagBits bit, const char* shader, const char* variant) {
        VkPipelineShaderStageCreateInfo s{};
        s.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        s.stage = bit;
        s.module = module(shader, variant);
        s.pName = "main";
        stages.push_back(s);
    };
    if (occluders) {
        stage(VK_SHADER_STAGE_VERTEX_BIT, "occluder.vert.glsl", "");
        stage(VK_SHADER_STAGE_FRAGMENT_BIT, "occluder.frag.glsl", "");
    } else {
        stage(VK_SHADER_STAGE_VERTEX_BIT, "patch.vert.glsl", kind == DrawKind::patch_list ? "PATCHCULL_DRAW_LIST" : "");
        stage(VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT, "patch.tesc.glsl",
              kind == DrawKind::mark_front ? "PATCHCULL_MARK_FRONT" : "");
        stage(VK_SHADER_STAGE_TESSELLATION_EVALUATION_BIT, "patch.tese.glsl", "");
        stage(VK_SHADER_STAGE_FRAGMENT_BIT, "patch.frag.glsl",
              kind == DrawKind::mark_front ? "PATCHCULL_MARK_FRONT" : "");
    }
    VkPipelineVertexInputStateCreateInfo vertex_input{};
    vertex_input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    VkPipelineInputAssemblyStateCreateInfo assembly{};
    assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    assembly.topology = occluders ? VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST : VK_PRIMITIVE_TOPOLOGY_PATCH_LIST;
    VkPipelineTessellationStateCreateInfo tessellation{};
    tessellation.sType = VK_STRUCTURE_TYPE_PIPELINE_TESSELLATION_STATE_CREATE_INFO;
    tessellation.patchControlPoints = 16;
    VkPipelineViewportStateCreateInfo viewport{};
    viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{};
    raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = kind == DrawKind::occluders_one_sided ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{};
    multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    const bool mark = kind == DrawKind::mark_front;
    VkPipelineDepthStencilStateCreateInfo depth{};
    depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    depth.depthTestEnable = VK_TRUE;
    depth.depthWriteEnable = mark ? VK_FALSE : VK_TRUE;
    depth.depthCompareOp = mark ? VK_COMPARE_OP_EQUAL : (reversed ? VK_COMPARE_OP_GREATER : VK_COMPARE_OP_LESS);
    // Both attachments alike (no independentBlend needed); the id attachment has R only.
    VkPipelineColorBlendAttachmentState blend[2]{};
    for (VkPipelineColorBlendAttachmentState& b : blend)
        b.colorWriteMask = mark ? 0u
                                : VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                                      VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendStateCreateInfo color{};
    color.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    color.attachmentCount = 2;
    color.pAttachments = blend;
    const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{};
    dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamic_states;
    const VkFormat formats[] = {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R32_UINT};
    VkPipelineRenderingCreateInfo rendering{};
    rendering.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO;
    rendering.colorAttachmentCount = 2;
    rendering.pColorAttachmentFormats = formats;
    rendering.depthAttachmentFormat = VK_FORMAT_D32_SFLOAT;
    VkGraphicsPipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    info.pNext = &rendering;
    info.stageCount = static_cast<std::uint32_t>(stages.size());
    info.pStages = stages.data();
    info.pVertexInputState = &vertex_input;
    info.pInputAssemblyState = &assembly;
    info.pTessellationState = occluders ? nullptr : &tessellation;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &color;
    info.pDynamicState = &dynamic;
    info.layout = occluders ? occluder_layout_ : patch_layout_;
    check_renderer(vkCreateGraphicsPipelines(device_->device(), VK_NULL_HANDLE, 1, &info, nullptr, &pipeline),
                   "vkCreateGraphicsPipelines");
    return pipeline;
}

}  // namespace patchcull::vk::detail
