// FrustumPass (patchcull/vk/vk_passes.h): cull_frustum_scalar on Vulkan, shaders/frustum.comp.glsl.
#include "vk_common.h"

namespace patchcull::vk {

FrustumPass::FrustumPass(PassContext& context) : context_(&context.impl()) {}

void FrustumPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, const FrustumPlanes& planes,
                      const BufferRange& plane_values) {
    const char* who = "FrustumPass";
    PassContext::Impl& context = *context_;
    const VkDeviceSize end = patches.first + patches.count;
    context.check_range(who, "control-point", patches.control_points, end * 256, false);
    context.check_range(who, "flag", patches.flags, end * 4, false);
    context.check_range(who, "margin", patches.margins, end * 4, true);
    context.check_range(who, "plane-value", plane_values, end * 6 * sizeof(float), true);
    if (patches.count == 0) return;
    const detail::Pipeline& p = context.pipeline("frustum.comp.glsl", "",
                                                 {shared::kBindingControlPoints, shared::kBindingCullFlags,
                                                  shared::kBindingMaxDisplacement, shared::kBindingPlaneValues},
                                                 sizeof(pp::FrustumParams));
    pp::FrustumParams params;
    detail::store_planes(planes, params);
    params.has_margins = patches.margins.buffer ? 1u : 0u;
    params.write_plane_values = plane_values.buffer ? 1u : 0u;
    const detail::Binding bindings[] = {{shared::kBindingControlPoints, patches.control_points},
                                        {shared::kBindingCullFlags, patches.flags},
                                        {shared::kBindingMaxDisplacement, patches.margins},
                                        {shared::kBindingPlaneValues, plane_values}};
    context.record(cmd, p, bindings, 4, params, patches.first, patches.count, shared::kCullGroupSize);
}

void FrustumPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, const CullView& view,
                      const BufferRange& plane_values) {
    run(cmd, patches, view.planes, plane_values);
}

}  // namespace patchcull::vk
