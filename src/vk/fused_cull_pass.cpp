// FusedCullPass (patchcull/vk/vk_passes.h): the frustum, cone back-patch and Hi-Z tests in one
// dispatch on Vulkan, shaders/fused_cull.comp.glsl (ncone: its PATCHCULL_NCONE module); its
// 160-byte parameter block is the context's uniform buffer (shaders/api.h).
#include <algorithm>
#include <string>

#include "vk_common.h"

namespace patchcull::vk {

static_assert(sizeof(pp::FusedCullParams) == 160);

FusedCullPass::FusedCullPass(PassContext& context) : context_(&context.impl()) {}

void FusedCullPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, std::uint32_t tests,
                        const Mat4& object_to_clip, ClipDepth depth, BackpatchMethod method, Vec3 eye,
                        const HiZImage& hiz) {
    const char* who = "FusedCullPass";
    PassContext::Impl& context = *context_;
    const VkDeviceSize end = patches.first + patches.count;
    context.check_range(who, "control-point", patches.control_points, end * 256, false);
    context.check_range(who, "flag", patches.flags, end * 4, false);
    context.check_range(who, "margin", patches.margins, end * 4, true);
    if (tests & ~(kCullFrustum | kCullBackPatch | kCullOcclusion))
        throw Error("Vulkan: FusedCullPass: tests must be kCullFrustum, kCullBackPatch and kCullOcclusion bits");
    const bool backpatch = (tests & kCullBackPatch) != 0;
    const bool occlusion = (tests & kCullOcclusion) != 0;
    if (backpatch && method != BackpatchMethod::tcone && method != BackpatchMethod::ncone)
        throw Error(std::string("Vulkan: FusedCullPass: ") + backpatch_method_name(method) +
                    " is not fused (its own pass runs it)");
    if (!hiz.all_levels || hiz.width < 1 || hiz.height < 1)
        throw Error("Vulkan: FusedCullPass: no Hi-Z pyramid (bound in every run, read with kCullOcclusion)");
    if (occlusion && hiz.reversed != is_reversed(depth))
        throw Error(std::string("Vulkan: FusedCullPass: the matrix is declared ") + clip_depth_name(depth) +
                    " but the Hi-Z pyramid was built from a " + (hiz.reversed ? "reversed" : "forward") +
                    " depth buffer (HiZBuildPass::run's convention)");
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, depth);  // refuses a contradiction
    if (patches.count == 0 || tests == 0) return;
    const bool ncone = backpatch && method == BackpatchMethod::ncone;
    const detail::Pipeline& p = context.pipeline("fused_cull.comp.glsl", ncone ? "PATCHCULL_NCONE" : "",
                                                 {shared::kBindingControlPoints,
                                                  shared::kBindingCullFlags,
                                                  shared::kBindingMaxDisplacement,
                                                  {api::kTextureHiZBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
                                                  {api::kParamsBinding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER}},
                                                 0);
    pp::FusedCullParams params;
    params.plane_depth = {planes.near_w, planes.far_w, planes.far_limit, 0.0f};
    for (int r = 0; r < 4; ++r)
        params.clip_rows[r] = {planes.clip_rows[r].x, planes.clip_rows[r].y, planes.clip_rows[r].z,
                               planes.clip_rows[r].w};
    float nl[8] = {};
    for (int q = 0; q < 6; ++q) nl[q] = planes.normal_length[q];
    params.plane_normal_length[0] = {nl[0], nl[1], nl[2], nl[3]};
    params.plane_normal_length[1] = {nl[4], nl[5], nl[6], nl[7]};
    params.eye = {eye.x, eye.y, eye.z, 1.0f};
    params.has_margins = patches.margins.buffer ? 1u : 0u;
    params.tests = tests;
    if (occlusion) {
        params.screen_width = hiz.width;
        params.screen_height = hiz.height;
        params.hiz_levels = HiZPyramid::level_count(hiz.width, hiz.height);
    }
    params.zero = 0.0f;

    const BufferRange* ranges[3] = {&patches.control_points, &patches.flags, &patches.margins};
    const std::uint32_t buffer_bindings[3] = {shared::kBindingControlPoints, shared::kBindingCullFlags,
                                              shared::kBindingMaxDisplacement};
    VkDescriptorBufferInfo buffers[4]{};
    VkWriteDescriptorSet writes[5]{};
    for (int i = 0; i < 3; ++i) {
        const BufferRange& r = *ranges[i];
        buffers[i] = r.buffer ? VkDescriptorBufferInfo{r.buffer, r.offset, r.size}
                              : VkDescriptorBufferInfo{context.placeholder, 0, VK_WHOLE_SIZE};
        writes[i].dstBinding = buffer_bindings[i];
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &buffers[i];
    }
    buffers[3] = {context.param_buffer, 0, sizeof params};
    writes[3].dstBinding = api::kParamsBinding;
    writes[3].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    writes[3].pBufferInfo = &buffers[3];
    const VkDescriptorImageInfo image{context.sampler, hiz.all_levels, VK_IMAGE_LAYOUT_GENERAL};
    writes[4].dstBinding = api::kTextureHiZBinding;
    writes[4].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    writes[4].pImageInfo = &image;
    for (VkWriteDescriptorSet& w : writes) {
        w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w.descriptorCount = 1;
    }
    context.vk.CmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    context.vk.CmdPushDescriptorSetKHR(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 5, writes);
    const std::size_t per_dispatch = std::size_t{65535} * shared::kCullGroupSize;
    for (std::size_t offset = 0; offset < patches.count; offset += per_dispatch) {
        const std::size_t n = std::min(per_dispatch, patches.count - offset);
        params.first_patch = static_cast<pp::uint>(patches.first + offset);
        params.patch_count = static_cast<pp::uint>(n);
        context.update_params(cmd, &params, sizeof params);
        context.vk.CmdDispatch(
            cmd, static_cast<std::uint32_t>((n + shared::kCullGroupSize - 1) / shared::kCullGroupSize), 1, 1);
    }
    context.barrier_after(cmd);
}

}  // namespace patchcull::vk
