// CullStatusPass (patchcull/gl/gl_passes.h): the two ends of the flag chain,
// shaders/cull_status.comp.glsl; the end's draw-list append (PC_STATUS_APPEND) finished by
// compact.comp.glsl's kCompactFinish.
#include <array>

#include "pass_common.h"
#include "patchcull/gl/gl_compaction.h"

namespace patchcull::gl {

namespace {
// The end's draw-list append: the selection and where it goes (none when out is null).
struct StatusAppend {
    std::uint32_t mask = 0, value = 0;
    const DrawListBuffers* out = nullptr;
};
}  // namespace

struct CullStatusPass::Impl {
    explicit Impl(PassContext::Impl& c) : context(c) {}
    ~Impl() {
        const GLuint buffers[] = {scratch_counters, append_words};
        glDeleteBuffers(2, buffers);
    }
    PassContext::Impl& context;
    detail::ParamBlock block;
    detail::ParamBlock finish_block;  // the append's commands step (CompactParams)
    GLuint scratch_counters = 0;      // bound when the caller counts nothing
    GLuint append_words = 0;          // the append's kStatusAppendWords words (shared.h)

    void run(const PatchBuffers& patches, pp::uint mode, GLuint counters, std::size_t offset,
             const StatusAppend& append = {}) {
        const char* who = "CullStatusPass";
        detail::begin_pass(who);
        detail::check_patch_buffers(who, patches, /*with_points=*/false);
        if (counters) detail::check_buffer_size(who, "counter", counters, offset + shared::kCounterCount * 4);
        pp::CompactParams finish;
        if (append.out) finish = detail::check_draw_list(who, context, patches, *append.out);
        if (patches.count == 0 && !append.out) return;
        if (!counters) {
            if (!scratch_counters) {
                glCreateBuffers(1, &scratch_counters);
                glNamedBufferStorage(scratch_counters, shared::kCounterCount * 4, nullptr, 0);
            }
            counters = scratch_counters;
            offset = 0;
        }
        if (append.out) {
            if (!append_words) {
                glCreateBuffers(1, &append_words);
                glNamedBufferStorage(append_words, shared::kStatusAppendWords * 4, nullptr, GL_DYNAMIC_STORAGE_BIT);
            }
            // The total starts at 0; the range's first entry and the selection.
            const std::array<std::uint32_t, shared::kStatusAppendWords> words = {
                0u, static_cast<std::uint32_t>(append.out->list_first), append.mask, append.value};
            glNamedBufferSubData(append_words, 0, sizeof(words), words.data());
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingCompactSums, append_words);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingDrawList, append.out->list);
        }
        if (patches.count) {
            pp::CullStatusParams params;
            params.mode = mode;
            params.has_margins = patches.margins ? 1u : 0u;
            glUseProgram(context.program("cull_status.comp.glsl", append.out ? "#define PC_STATUS_APPEND 1\n" : ""));
            detail::bind_patch_buffers(patches);
            glBindBufferRange(GL_SHADER_STORAGE_BUFFER, shared::kBindingCullCounters, counters,
                              static_cast<GLintptr>(offset), shared::kCounterCount * 4);
            detail::dispatch_patches(block, params, patches.first, patches.count, shared::kCullGroupSize);
        }
        if (append.out) {
            // compact.comp.glsl's commands step, as CompactPass's append ends: the total at word 0.
            const DrawListBuffers& out = *append.out;
            glUseProgram(context.program("compact.comp.glsl"));
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingDrawCommands, out.command);
            if (out.draw_count) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingDrawCount, out.draw_count);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
            detail::dispatch_finish(finish_block, finish, patches.count,
                                    compact_command_count(patches.count, out.patches_per_command),
                                    shared::kStatusAppendTotal);
            glMemoryBarrier(GL_COMMAND_BARRIER_BIT);
        }
        detail::finish_pass(who);
    }
};

CullStatusPass::CullStatusPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
CullStatusPass::CullStatusPass(CullStatusPass&&) noexcept = default;
CullStatusPass& CullStatusPass::operator=(CullStatusPass&&) noexcept = default;
CullStatusPass::~CullStatusPass() = default;

void CullStatusPass::begin(const PatchBuffers& patches) { impl_->run(patches, shared::kStatusBegin, 0, 0); }
void CullStatusPass::end(const PatchBuffers& patches, std::uint32_t counters, std::size_t counters_offset) {
    impl_->run(patches, shared::kStatusEnd, counters, counters_offset);
}
void CullStatusPass::end(const PatchBuffers& patches, std::uint32_t counters, std::size_t counters_offset,
                         const DrawListBuffers& out, std::uint32_t mask, std::uint32_t value) {
    impl_->run(patches, shared::kStatusEnd, counters, counters_offset, {mask, value, &out});
}

}  // namespace patchcull::gl
