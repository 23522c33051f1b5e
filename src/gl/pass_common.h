// What the cull passes (patchcull/gl/gl_passes.h) share, not a public header: the PassContext's
// program cache and fma mode, the parameter-block upload, and the one rule for splitting a patch
// range into dispatches.
#pragma once

#include <epoxy/gl.h>

#include <cstddef>
#include <map>
#include <string>

#include "gl_util.h"
#include "pass_params.h"
#include "patchcull/gl/gl_passes.h"
#include "shared.h"

namespace patchcull::gl {

namespace pp = pass_params;
struct DrawListBuffers;  // gl_compaction.h

struct PassContext::Impl {
    bool fma_via_double = false;
    bool native_div_sqrt = false;  // PATCHCULL_NATIVE_DIV_SQRT (shaders/backpatch_exact.h)
    bool software = false;
    std::map<std::string, GLuint> programs;  // key: shader name + "\n" + defines
    GLint64 max_storage_block = -1;          // GL_MAX_SHADER_STORAGE_BLOCK_SIZE, read on the first source run
    GLuint probe_in = 0, probe_out = 0;
    ~Impl();
    /// The program of compute shader `shader` with `defines` (lines "#define X 1\n"), plus
    /// PATCHCULL_FMA_VIA_DOUBLE when fma_via_double and PATCHCULL_NATIVE_DIV_SQRT when
    /// native_div_sqrt; compiled on first use.
    GLuint program(const char* shader, const std::string& defines = {});
    /// Deletes every program (they are compiled again with the modes as they are then).
    void drop_programs();
};

namespace detail {

/// Throws unless the buffers of `patches` exist and hold its range (control points 256 bytes per
/// patch, unless with_points is false: flags and margins only; flags and margins 4 bytes per
/// patch). `who` starts the message.
void check_patch_buffers(const char* who, const PatchBuffers& patches, bool with_points = true);
/// Throws unless buffer is a buffer of at least bytes bytes.
void check_buffer_size(const char* who, const char* what, GLuint buffer, std::size_t bytes);

/// A pass's parameter block: a small uniform buffer, uploaded whole before each dispatch and bound
/// at kUniformPassParams.
class ParamBlock {
public:
    ParamBlock();
    ~ParamBlock();
    ParamBlock(const ParamBlock&) = delete;
    ParamBlock& operator=(const ParamBlock&) = delete;
    template <class Params>
    void upload(const Params& params, GLuint binding = shared::kUniformPassParams) {
        if (!buffer_) create(sizeof(Params));
        glNamedBufferSubData(buffer_, 0, sizeof(Params), &params);
        glBindBufferBase(GL_UNIFORM_BUFFER, binding, buffer_);
    }

private:
    void create(std::size_t size);
    GLuint buffer_ = 0;
};

/// What every pass keeps: its context's program cache and its parameter block (and the
/// patch-source block of the runs over a GpuPatchSource, created on the first).
struct PassState {
    explicit PassState(PassContext::Impl& c) : context(c) {}
    PassContext::Impl& context;
    ParamBlock block;
    ParamBlock source_block;
};

/// Throws (one line, starting with "GL: <who>: ") unless source is valid and its buffers hold
/// what its range reads (gl_passes.h's GpuPatchSource); returns its parameter block.
pp::PatchSourceParams check_patch_source(const char* who, PassContext::Impl& context, const GpuPatchSource& source);

/// The defines of a pass's program over source: PC_PATCH_SOURCE, and PC_PATCH_SOURCE_GREGORY for
/// a Gregory source.
const char* patch_source_defines(const GpuPatchSource& source);
/// "#define PC_MARGINS 1" or 0 (shaders/flag_chain.h): a program for passes with margins and one
/// for those without.
inline const char* margins_define(bool has_margins) {
    return has_margins ? "#define PC_MARGINS 1\n" : "#define PC_MARGINS 0\n";
}

/// Binds the chain's buffers of source (flags, margins when given) and its own (vertices,
/// indices, masks), uploads params into state.source_block at kUniformPatchSource, and issues a
/// storage barrier so that shader writes to the caller's buffers just before are seen.
void bind_patch_source(PassState& state, const GpuPatchSource& source, const pp::PatchSourceParams& params);

/// The rule for large ranges: a range of `count` patches, `patches_per_group` per work group, is
/// covered by dispatches of at most 65535 work groups (the GL minimum of the x count); before
/// each, params.first_patch and params.patch_count are set to its sub-range (first + offset) and
/// the block is uploaded.
template <class Params>
void dispatch_patches(ParamBlock& block, Params& params, std::size_t first, std::size_t count,
                      std::size_t patches_per_group) {
    const std::size_t per_dispatch = 65535 * patches_per_group;
    for (std::size_t offset = 0; offset < count; offset += per_dispatch) {
        const std::size_t n = std::min(per_dispatch, count - offset);
        params.first_patch = static_cast<pp::uint>(first + offset);
        params.patch_count = static_cast<pp::uint>(n);
        block.upload(params);
        glDispatchCompute(static_cast<GLuint>((n + patches_per_group - 1) / patches_per_group), 1, 1);
    }
}

/// The start of every run(): throws when a GL error is pending (left by the caller), so that
/// finish_pass's check reports only the pass's own.
void begin_pass(const char* who);

/// Binds the chain's buffers (control points, flags, margins when given).
void bind_patch_buffers(const PatchBuffers& patches);

/// The end of every run(): no program, the barrier of the state contract, GL error check.
void finish_pass(const char* who);

/// Copies a FrustumPlanes into a parameter block's clip_rows / plane_normal_length.
void store_planes(const FrustumPlanes& planes, pp::vec4 clip_rows[4], pp::vec4 normal_length[2], pp::vec4& depth);

// compact_pass.cpp, shared with CullStatusPass::end's draw-list append (cull_status_pass.cpp):
/// CompactPass's checks of a DrawListBuffers for patches (one-line Error naming who), and the
/// parameter block they start.
pp::CompactParams check_draw_list(const char* who, PassContext::Impl& context, const PatchBuffers& patches,
                                  const DrawListBuffers& out);
/// compact.comp.glsl's kCompactFinish step: the commands and draw count from the total at
/// total_word of the sums.
void dispatch_finish(ParamBlock& block, pp::CompactParams& params, std::size_t count, std::size_t commands,
                     std::size_t total_word);

}  // namespace detail
}  // namespace patchcull::gl
