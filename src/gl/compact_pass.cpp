// CompactPass (patchcull/gl/gl_compaction.h): the flag words of a range -> a draw list and an
// indirect command, shaders/compact.comp.glsl.
#include "patchcull/gl/gl_compaction.h"

#include <algorithm>
#include <string>

#include "pass_common.h"

namespace patchcull::gl {

static_assert(sizeof(pp::CompactParams) == 48);

std::string_view compact_method_name(CompactMethod method) {
    if (method == CompactMethod::fused_append) return "fused";
    return method == CompactMethod::atomic_append ? "append" : "scan";
}

std::size_t compact_command_count(std::size_t count, std::size_t patches_per_command) {
    if (patches_per_command == 0 || count == 0) return 1;
    return (count + patches_per_command - 1) / patches_per_command;
}

namespace detail {

// CompactPass's checks of a range and its DrawListBuffers (Error "GL: <who>: ..."), and the
// parameters of the commands' step (kCompactFinish) for them. CullStatusPass's append uses them
// too (declared in cull_status_pass.cpp).
pp::CompactParams check_draw_list(const char* who, PassContext::Impl& context, const PatchBuffers& patches,
                                  const DrawListBuffers& out) {
    const std::string prefix = std::string("GL: ") + who + ": ";
    auto check_offset = [&prefix](const char* what, std::size_t offset) {
        if (offset % 4 != 0)
            throw Error(prefix + what + " offset " + std::to_string(offset) + " is not a multiple of 4");
    };
    if (out.list_first + patches.count > 0xFFFFFFFFu / 16)
        throw Error(prefix + "list_first + count past 2^28 entries (16 vertices per patch)");
    check_offset("command", out.command_offset);
    check_buffer_size(who, "draw-list", out.list, (out.list_first + patches.count) * 4);
    const std::size_t commands = compact_command_count(patches.count, out.patches_per_command);
    check_buffer_size(who, "indirect-command", out.command,
                      out.command_offset + commands * sizeof(DrawArraysIndirectCommand));
    if (out.draw_count) {
        check_offset("draw-count", out.draw_count_offset);
        check_buffer_size(who, "draw-count", out.draw_count, out.draw_count_offset + 4);
    }
    // The flags and the list are read as storage blocks from byte 0: the driver's limit holds them.
    if (context.max_storage_block < 0) glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &context.max_storage_block);
    const std::size_t limit =
        context.max_storage_block > 0 ? static_cast<std::size_t>(context.max_storage_block) : std::size_t{0xFFFFFFFFu};
    const std::size_t reach = std::max(patches.first, out.list_first) + patches.count;
    if (reach * 4 > limit)
        throw Error(prefix + "the flags or the list reach byte " + std::to_string(reach * 4) +
                    ", past GL_MAX_SHADER_STORAGE_BLOCK_SIZE (" + std::to_string(limit) + ")");
    pp::CompactParams params;
    params.list_first = static_cast<pp::uint>(out.list_first);
    params.command_word = static_cast<pp::uint>(out.command_offset / 4);
    params.count_word = static_cast<pp::uint>(out.draw_count_offset / 4);
    params.write_count = out.draw_count ? 1u : 0u;
    // K in [1, max(count, 1)]: the same commands as the header's, and no overflow in the shader.
    const std::size_t range = std::max<std::size_t>(patches.count, 1);
    params.patches_per_command =
        static_cast<pp::uint>(out.patches_per_command == 0 ? range : std::min(out.patches_per_command, range));
    return params;
}

// kCompactFinish (the bound program: compact.comp.glsl) over the range's commands, from the total
// at word total_word of the buffer at kBindingCompactSums: one invocation per command.
void dispatch_finish(ParamBlock& block, pp::CompactParams& params, std::size_t count, std::size_t commands,
                     std::size_t total_word) {
    params.mode = shared::kCompactFinish;
    params.patch_count = static_cast<pp::uint>(count);
    params.group_count = static_cast<pp::uint>(total_word);
    const std::size_t per_dispatch = std::size_t{65535} * shared::kCompactGroupSize;
    for (std::size_t c = 0; c < commands; c += per_dispatch) {
        const std::size_t n = std::min(per_dispatch, commands - c);
        params.group_base = static_cast<pp::uint>(c);
        block.upload(params);
        glDispatchCompute(static_cast<GLuint>((n + shared::kCompactGroupSize - 1) / shared::kCompactGroupSize), 1, 1);
    }
}

}  // namespace detail

struct CompactPass::Impl {
    explicit Impl(PassContext::Impl& c) : context(c) {}
    ~Impl() { glDeleteBuffers(1, &sums); }
    PassContext::Impl& context;
    detail::ParamBlock block;
    GLuint sums = 0;  // the scan's work-group sums
    std::size_t sums_capacity = 0;

    // One dispatch per at most 65535 work groups of `group` patches over the range; group_base
    // counts the groups before.
    void dispatch_range(pp::CompactParams& params, std::size_t first, std::size_t count, std::size_t group) {
        const std::size_t per_dispatch = 65535 * group;
        for (std::size_t offset = 0; offset < count; offset += per_dispatch) {
            const std::size_t n = std::min(per_dispatch, count - offset);
            params.first_patch = static_cast<pp::uint>(first + offset);
            params.patch_count = static_cast<pp::uint>(n);
            params.group_base = static_cast<pp::uint>(offset / group);
            block.upload(params);
            glDispatchCompute(static_cast<GLuint>((n + group - 1) / group), 1, 1);
        }
    }

    void dispatch_one(pp::CompactParams& params, pp::uint mode) {
        params.mode = mode;
        block.upload(params);
        glDispatchCompute(1, 1, 1);
    }

    void run(const PatchBuffers& patches, pp::uint mask, pp::uint value, const DrawListBuffers& out,
             CompactMethod method) {
        const char* who = "CompactPass";
        detail::begin_pass(who);
        detail::check_patch_buffers(who, patches, /*with_points=*/false);
        pp::CompactParams params = detail::check_draw_list(who, context, patches, out);
        params.mask = mask;
        params.value = value;
        const std::size_t commands = compact_command_count(patches.count, out.patches_per_command);
        const bool scan = method == CompactMethod::prefix_scan;
        // Patches per work group: one per invocation in the append, a run of kCompactScanRun in the scan.
        const std::size_t group = shared::kCompactGroupSize * (scan ? shared::kCompactScanRun : 1);
        const std::size_t groups = (patches.count + group - 1) / group;
        params.group_count = static_cast<pp::uint>(groups);
        // The scan's group sums and the total after them; the append's total alone.
        const std::size_t sum_words = scan ? groups + 1 : 1;
        if (sum_words > sums_capacity) {
            const std::size_t capacity = std::max<std::size_t>(sum_words, 2 * sums_capacity);
            glDeleteBuffers(1, &sums);
            glCreateBuffers(1, &sums);
            glNamedBufferStorage(sums, static_cast<GLsizeiptr>(capacity * 4), nullptr, 0);
            sums_capacity = capacity;
        }

        glUseProgram(context.program("compact.comp.glsl", scan ? "#define PC_COMPACT_SCAN 1\n" : ""));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingCullFlags, patches.flags);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingDrawList, out.list);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingDrawCommands, out.command);
        if (out.draw_count) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingDrawCount, out.draw_count);
        // Earlier shader writes to the flags (the chain's passes) and to these buffers are seen.
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingCompactSums, sums);
        if (scan && patches.count <= shared::kCompactSingleGroupPatches) {
            // A small range: the whole scan and the finish in one dispatch of one work group.
            params.first_patch = static_cast<pp::uint>(patches.first);
            params.patch_count = static_cast<pp::uint>(patches.count);
            dispatch_one(params, shared::kCompactSingleGroup);
            glMemoryBarrier(GL_COMMAND_BARRIER_BIT);
            detail::finish_pass(who);
            return;
        }
        if (scan) {
            if (patches.count) {
                params.mode = shared::kCompactGroupCounts;
                dispatch_range(params, patches.first, patches.count, group);
                glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
            }
            dispatch_one(params, shared::kCompactScanSums);
            if (patches.count) {
                glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
                params.mode = shared::kCompactScatter;
                dispatch_range(params, patches.first, patches.count, group);
            }
        } else {
            dispatch_one(params, shared::kCompactInit);
            if (patches.count) {
                glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
                params.mode = shared::kCompactAppend;
                dispatch_range(params, patches.first, patches.count, group);
            }
        }
        // The commands and the draw count from the total (sums[groups] after the scan, sums[0]
        // after the append), one invocation per command.
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        detail::dispatch_finish(block, params, patches.count, commands, scan ? groups : 0);
        glMemoryBarrier(GL_COMMAND_BARRIER_BIT);
        detail::finish_pass(who);
    }
};

CompactPass::CompactPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
CompactPass::CompactPass(CompactPass&&) noexcept = default;
CompactPass& CompactPass::operator=(CompactPass&&) noexcept = default;
CompactPass::~CompactPass() = default;

void CompactPass::run(const PatchBuffers& patches, std::uint32_t mask, std::uint32_t value, const DrawListBuffers& out,
                      CompactMethod method) {
    impl_->run(patches, mask, value, out, method);
}

}  // namespace patchcull::gl
