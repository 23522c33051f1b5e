// CullStatusPass (patchcull/gl/gl_passes.h): the two ends of the flag chain,
// shaders/cull_status.comp.glsl.
#include "pass_common.h"

namespace patchcull::gl {

struct CullStatusPass::Impl {
    explicit Impl(PassContext::Impl& c) : context(c) {}
    ~Impl() { glDeleteBuffers(1, &scratch_counters); }
    PassContext::Impl& context;
    detail::ParamBlock block;
    GLuint scratch_counters = 0;  // bound when the caller counts nothing

    void run(const PatchBuffers& patches, pp::uint mode, GLuint counters, std::size_t offset) {
        detail::begin_pass("CullStatusPass");
        detail::check_patch_buffers("CullStatusPass", patches, /*with_points=*/false);
        if (counters)
            detail::check_buffer_size("CullStatusPass", "counter", counters, offset + shared::kCounterCount * 4);
        if (patches.count == 0) return;
        if (!counters) {
            if (!scratch_counters) {
                glCreateBuffers(1, &scratch_counters);
                glNamedBufferStorage(scratch_counters, shared::kCounterCount * 4, nullptr, 0);
            }
            counters = scratch_counters;
            offset = 0;
        }
        pp::CullStatusParams params;
        params.mode = mode;
        params.has_margins = patches.margins ? 1u : 0u;
        glUseProgram(context.program("cull_status.comp.glsl"));
        detail::bind_patch_buffers(patches);
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, shared::kBindingCullCounters, counters,
                          static_cast<GLintptr>(offset), shared::kCounterCount * 4);
        detail::dispatch_patches(block, params, patches.first, patches.count, shared::kCullGroupSize);
        detail::finish_pass("CullStatusPass");
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

}  // namespace patchcull::gl
