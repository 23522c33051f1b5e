// CullStatusPass (patchcull/vk/vk_passes.h): the two ends of the flag chain on Vulkan,
// shaders/cull_status.comp.glsl.
#include "vk_common.h"

namespace patchcull::vk {

namespace {

void record_status(PassContext::Impl& context, VkCommandBuffer cmd, const PatchBuffers& patches, pp::uint mode,
                   const BufferRange& counters) {
    const char* who = "CullStatusPass";
    const VkDeviceSize end = patches.first + patches.count;
    context.check_range(who, "flag", patches.flags, end * 4, false);
    context.check_range(who, "margin", patches.margins, end * 4, true);
    context.check_range(who, "counter", counters, shared::kCounterCount * 4, true);
    if (patches.count == 0) return;
    const detail::Pipeline& p =
        context.pipeline("cull_status.comp.glsl", "",
                         {shared::kBindingCullFlags, shared::kBindingMaxDisplacement, shared::kBindingCullCounters},
                         sizeof(pp::CullStatusParams));
    pp::CullStatusParams params;
    params.mode = mode;
    params.has_margins = patches.margins.buffer ? 1u : 0u;
    // Without counters the shader's adds go to the context's placeholder buffer (never read).
    const detail::Binding bindings[] = {{shared::kBindingCullFlags, patches.flags},
                                        {shared::kBindingMaxDisplacement, patches.margins},
                                        {shared::kBindingCullCounters, counters}};
    context.record(cmd, p, bindings, 3, params, patches.first, patches.count, shared::kCullGroupSize);
}

}  // namespace

CullStatusPass::CullStatusPass(PassContext& context) : context_(&context.impl()) {}

void CullStatusPass::begin(VkCommandBuffer cmd, const PatchBuffers& patches) {
    record_status(*context_, cmd, patches, shared::kStatusBegin, {});
}

void CullStatusPass::end(VkCommandBuffer cmd, const PatchBuffers& patches, const BufferRange& counters) {
    record_status(*context_, cmd, patches, shared::kStatusEnd, counters);
}

}  // namespace patchcull::vk
