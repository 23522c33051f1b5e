// BackpatchConePass (patchcull/vk/vk_passes.h): cull_tcone_scalar and cull_ncone_scalar on Vulkan,
// shaders/backpatch_cones.comp.glsl (ncone: its PATCHCULL_NCONE module).
#include <string>

#include "vk_common.h"

namespace patchcull::vk {

BackpatchConePass::BackpatchConePass(PassContext& context) : context_(&context.impl()) {}

void BackpatchConePass::run(VkCommandBuffer cmd, const PatchBuffers& patches, BackpatchMethod method, Vec3 eye,
                            const BufferRange& cone_values) {
    const char* who = "BackpatchConePass";
    if (method != BackpatchMethod::tcone && method != BackpatchMethod::ncone)
        throw Error(std::string("Vulkan: BackpatchConePass runs tcone and ncone, not ") +
                    backpatch_method_name(method));
    PassContext::Impl& context = *context_;
    const VkDeviceSize end = patches.first + patches.count;
    context.check_range(who, "control-point", patches.control_points, end * 256, false);
    context.check_range(who, "flag", patches.flags, end * 4, false);
    context.check_range(who, "margin", patches.margins, end * 4, true);
    context.check_range(who, "cone-value", cone_values, end * shared::kConeValues * sizeof(float), true);
    if (patches.count == 0) return;
    const bool ncone = method == BackpatchMethod::ncone;
    const detail::Pipeline& p = context.pipeline("backpatch_cones.comp.glsl", ncone ? "PATCHCULL_NCONE" : "",
                                                 {shared::kBindingControlPoints, shared::kBindingCullFlags,
                                                  shared::kBindingMaxDisplacement, shared::kBindingConeValues},
                                                 sizeof(pp::BackpatchConeParams));
    pp::BackpatchConeParams params;
    params.eye = {eye.x, eye.y, eye.z, 1.0f};
    params.has_margins = patches.margins.buffer ? 1u : 0u;
    params.write_cones = cone_values.buffer ? 1u : 0u;
    params.zero = 0.0f;
    const detail::Binding bindings[] = {{shared::kBindingControlPoints, patches.control_points},
                                        {shared::kBindingCullFlags, patches.flags},
                                        {shared::kBindingMaxDisplacement, patches.margins},
                                        {shared::kBindingConeValues, cone_values}};
    context.record(cmd, p, bindings, 4, params, patches.first, patches.count, shared::kConeGroupSize);
}

}  // namespace patchcull::vk
