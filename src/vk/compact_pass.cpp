// CompactPass (patchcull/vk/vk_passes.h): the flag words of a range -> a draw list and indirect
// commands on Vulkan, shaders/compact.comp.glsl (the scan: its PC_COMPACT_SCAN module), the steps
// of gl_compaction.h's CompactPass with a compute barrier between them.
#include <algorithm>
#include <string>

#include "vk_common.h"

namespace patchcull::vk {

static_assert(sizeof(pp::CompactParams) == 48);

namespace {

// Patches per work group: one per invocation in the append, a run of kCompactScanRun in the scan.
std::size_t group_patches(CompactMethod method) {
    return shared::kCompactGroupSize * (method == CompactMethod::prefix_scan ? shared::kCompactScanRun : 1);
}

// Compute writes -> compute reads and writes: between the pass's own steps.
void barrier_between_steps(const PassContext::Impl& context, VkCommandBuffer cmd) {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    context.vk.CmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                                  &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace

std::size_t compact_command_count(std::size_t count, std::size_t patches_per_command) {
    if (patches_per_command == 0 || count == 0) return 1;
    return (count + patches_per_command - 1) / patches_per_command;
}

std::size_t compact_scratch_bytes(std::size_t count, CompactMethod method) {
    const std::size_t group = group_patches(method);
    const std::size_t groups = (count + group - 1) / group;
    return 4 * (method == CompactMethod::prefix_scan ? groups + 1 : 1);
}

CompactPass::CompactPass(PassContext& context) : context_(&context.impl()) {}

void CompactPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, std::uint32_t mask, std::uint32_t value,
                      const DrawListRanges& out, CompactMethod method) {
    const char* who = "CompactPass";
    PassContext::Impl& context = *context_;
    if (out.list_first + patches.count > 0xFFFFFFFFu / 16)
        throw Error("Vulkan: CompactPass: list_first + count past 2^28 entries (16 vertices per patch)");
    const std::size_t commands = compact_command_count(patches.count, out.patches_per_command);
    context.check_range(who, "flag", patches.flags, (patches.first + patches.count) * 4, false);
    context.check_range(who, "draw-list", out.list, (out.list_first + patches.count) * 4, false);
    context.check_range(who, "indirect-command", out.command, commands * 16, false);
    context.check_range(who, "draw-count", out.draw_count, 4, true);
    context.check_range(who, "scratch", out.scratch, compact_scratch_bytes(patches.count, method), false);
    const bool scan = method == CompactMethod::prefix_scan;
    const detail::Pipeline& p =
        context.pipeline("compact.comp.glsl", scan ? "PC_COMPACT_SCAN" : "",
                         {shared::kBindingCullFlags, shared::kBindingDrawList, shared::kBindingDrawCommands,
                          shared::kBindingDrawCount, shared::kBindingCompactSums},
                         sizeof(pp::CompactParams));
    pp::CompactParams params;
    params.mask = mask;
    params.value = value;
    params.list_first = static_cast<pp::uint>(out.list_first);
    params.command_word = 0;  // the command range is bound from its offset
    params.count_word = 0;
    params.write_count = out.draw_count.buffer ? 1u : 0u;
    // K in [1, max(count, 1)]: the same commands as the header's, and no overflow in the shader.
    const std::size_t range = std::max<std::size_t>(patches.count, 1);
    params.patches_per_command =
        static_cast<pp::uint>(out.patches_per_command == 0 ? range : std::min(out.patches_per_command, range));
    const std::size_t group = group_patches(method);
    const std::size_t groups = (patches.count + group - 1) / group;
    params.group_count = static_cast<pp::uint>(groups);

    const detail::Binding bindings[] = {{shared::kBindingCullFlags, patches.flags},
                                        {shared::kBindingDrawList, out.list},
                                        {shared::kBindingDrawCommands, out.command},
                                        {shared::kBindingDrawCount, out.draw_count},
                                        {shared::kBindingCompactSums, out.scratch}};
    context.bind(cmd, p, bindings, 5);
    auto push = [&] {
        context.vk.CmdPushConstants(cmd, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof params, &params);
    };
    // One dispatch per at most 65535 work groups of `group` patches; group_base counts the groups before.
    auto dispatch_range = [&] {
        const std::size_t per_dispatch = 65535 * group;
        for (std::size_t offset = 0; offset < patches.count; offset += per_dispatch) {
            const std::size_t n = std::min(per_dispatch, patches.count - offset);
            params.first_patch = static_cast<pp::uint>(patches.first + offset);
            params.patch_count = static_cast<pp::uint>(n);
            params.group_base = static_cast<pp::uint>(offset / group);
            push();
            context.vk.CmdDispatch(cmd, static_cast<std::uint32_t>((n + group - 1) / group), 1, 1);
        }
    };
    auto dispatch_one = [&](pp::uint mode) {
        params.mode = mode;
        push();
        context.vk.CmdDispatch(cmd, 1, 1, 1);
    };
    if (scan && patches.count <= shared::kCompactSingleGroupPatches) {
        // A small range: the whole scan and the finish in one dispatch of one work group.
        params.first_patch = static_cast<pp::uint>(patches.first);
        params.patch_count = static_cast<pp::uint>(patches.count);
        dispatch_one(shared::kCompactSingleGroup);
        context.barrier_after(cmd);
        return;
    }
    if (scan) {
        if (patches.count) {
            params.mode = shared::kCompactGroupCounts;
            dispatch_range();
            barrier_between_steps(context, cmd);
        }
        dispatch_one(shared::kCompactScanSums);
        if (patches.count) {
            barrier_between_steps(context, cmd);
            params.mode = shared::kCompactScatter;
            dispatch_range();
        }
    } else {
        dispatch_one(shared::kCompactInit);
        if (patches.count) {
            barrier_between_steps(context, cmd);
            params.mode = shared::kCompactAppend;
            dispatch_range();
        }
    }
    // The commands and the draw count from the total (sums[groups] after the scan, sums[0] after
    // the append), one invocation per command.
    barrier_between_steps(context, cmd);
    params.mode = shared::kCompactFinish;
    params.patch_count = static_cast<pp::uint>(patches.count);
    params.group_count = static_cast<pp::uint>(scan ? groups : 0);
    const std::size_t per_dispatch = std::size_t{65535} * shared::kCompactGroupSize;
    for (std::size_t c = 0; c < commands; c += per_dispatch) {
        const std::size_t n = std::min(per_dispatch, commands - c);
        params.group_base = static_cast<pp::uint>(c);
        push();
        context.vk.CmdDispatch(
            cmd, static_cast<std::uint32_t>((n + shared::kCompactGroupSize - 1) / shared::kCompactGroupSize), 1, 1);
    }
    context.barrier_after(cmd);
}

}  // namespace patchcull::vk
