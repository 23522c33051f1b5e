// FrustumDispPass (patchcull/vk/vk_passes.h): cull_frustum_disp_scalar (Sathe's displaced AABB) on
// Vulkan, shaders/frustum_disp.comp.glsl.
#include "vk_common.h"

namespace patchcull::vk {

FrustumDispPass::FrustumDispPass(PassContext& context) : context_(&context.impl()) {}

void FrustumDispPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, const Mat4& object_to_clip, ClipDepth depth,
                          const BufferRange& plane_values) {
    const char* who = "FrustumDispPass";
    PassContext::Impl& context = *context_;
    const VkDeviceSize end = patches.first + patches.count;
    context.check_range(who, "control-point", patches.control_points, end * 256, false);
    context.check_range(who, "flag", patches.flags, end * 4, false);
    context.check_range(who, "margin", patches.margins, end * 4, true);
    context.check_range(who, "plane-value", plane_values, end * 6 * sizeof(float), true);
    // The CPU kernel's planes (frustum.cpp): the same matrix, so the same corners.
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, depth);  // refuses a contradiction
    if (patches.count == 0) return;
    const detail::Pipeline& p = context.pipeline("frustum_disp.comp.glsl", "",
                                                 {shared::kBindingControlPoints, shared::kBindingCullFlags,
                                                  shared::kBindingMaxDisplacement, shared::kBindingPlaneValues},
                                                 sizeof(pp::FrustumDispParams));
    pp::FrustumDispParams params;
    for (int r = 0; r < 4; ++r)
        params.clip_rows[r] = {planes.clip_rows[r].x, planes.clip_rows[r].y, planes.clip_rows[r].z,
                               planes.clip_rows[r].w};
    params.plane_depth = {planes.near_w, planes.far_w, planes.far_limit, 0.0f};
    params.has_margins = patches.margins.buffer ? 1u : 0u;
    params.write_plane_values = plane_values.buffer ? 1u : 0u;
    const detail::Binding bindings[] = {{shared::kBindingControlPoints, patches.control_points},
                                        {shared::kBindingCullFlags, patches.flags},
                                        {shared::kBindingMaxDisplacement, patches.margins},
                                        {shared::kBindingPlaneValues, plane_values}};
    context.record(cmd, p, bindings, 4, params, patches.first, patches.count, shared::kCullGroupSize);
}

void FrustumDispPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, const CullView& view,
                          const BufferRange& plane_values) {
    run(cmd, patches, view.object_to_clip, view.depth, plane_values);
}

}  // namespace patchcull::vk
