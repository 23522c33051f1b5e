// BackpatchPtpPass (patchcull/vk/vk_passes.h): cull_ptp_scalar on Vulkan with Loop, Niessner &
// Eisenacher's 16 invocations per patch, shaders/backpatch_ptp.comp.glsl.
#include "vk_common.h"

namespace patchcull::vk {

BackpatchPtpPass::BackpatchPtpPass(PassContext& context) : context_(&context.impl()) {}

bool BackpatchPtpPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, const Mat4& object_to_clip, float alpha,
                           PtpRule rule, const BufferRange& plane_values) {
    const char* who = "BackpatchPtpPass";
    PassContext::Impl& context = *context_;
    const VkDeviceSize end = patches.first + patches.count;
    context.check_range(who, "control-point", patches.control_points, end * 256, false);
    context.check_range(who, "flag", patches.flags, end * 4, false);
    context.check_range(who, "margin", patches.margins, end * 4, true);
    context.check_range(who, "plane-value", plane_values, end * 128 * sizeof(float), true);
    // Rows x, y, w of s * object_to_clip, s = ptp_orientation_sign (backpatch.h), as the CPU
    // kernels' and the GL pass's: 0 means nothing may be culled.
    const int sign = ptp_orientation_sign(object_to_clip, alpha);
    if (sign == 0) return false;
    if (patches.count == 0) return true;
    const detail::Pipeline& p =
        context.pipeline("backpatch_ptp.comp.glsl", "",
                         {shared::kBindingControlPoints, shared::kBindingCullFlags, shared::kBindingMaxDisplacement,
                          shared::kBindingPtpPlanes, shared::kBindingPtpTables},
                         sizeof(pp::BackpatchPtpParams));
    pp::BackpatchPtpParams params;
    const float s = static_cast<float>(sign);
    const int src_row[3] = {0, 1, 3};  // x, y, w
    for (int r = 0; r < 3; ++r)
        params.rows[r] = {s * object_to_clip.at(src_row[r], 0), s * object_to_clip.at(src_row[r], 1),
                          s * object_to_clip.at(src_row[r], 2), s * object_to_clip.at(src_row[r], 3)};
    params.has_margins = patches.margins.buffer ? 1u : 0u;
    params.pcnt = rule == PtpRule::pcnt ? 1u : 0u;
    params.write_planes = plane_values.buffer ? 1u : 0u;
    params.zero = 0.0f;
    const detail::Binding bindings[] = {{shared::kBindingControlPoints, patches.control_points},
                                        {shared::kBindingCullFlags, patches.flags},
                                        {shared::kBindingMaxDisplacement, patches.margins},
                                        {shared::kBindingPtpPlanes, plane_values},
                                        {shared::kBindingPtpTables, context.ptp_tables()}};
    context.record(cmd, p, bindings, 5, params, patches.first, patches.count, shared::kPtpPatchesPerGroup);
    return true;
}

}  // namespace patchcull::vk
