// patchcull/gl/gl_compaction.h: draw only what survives (library patchcull_gl). CompactPass turns the
// flag words of a patch range (gl_passes.h) into a list of the patch indices a draw selection keeps
// and an indirect draw command over that list, on the GPU: the culled patches are never issued,
// instead of being issued and discarded by the TCS with tessellation levels 0 (patchcull_tcs.h).
// Counts stay on the GPU; nothing is read back.
//
// The draw (docs/ENGINE.md, "Draw only what survives"): bind the command buffer to
// GL_DRAW_INDIRECT_BUFFER and the draw-count buffer to GL_PARAMETER_BUFFER, and call
// glMultiDrawArraysIndirectCount(GL_PATCHES, command_offset, draw_count_offset, C, 0) (GL 4.6 or
// GL_ARB_indirect_parameters; else glMultiDrawArraysIndirect(GL_PATCHES, command_offset, C, 0),
// whose commands past the survivors have 0 vertices), C = compact_command_count(count, K), with
// GL_PATCH_VERTICES 16 and no vertex attributes. The vertex shader pulls its control point itself: point gl_VertexID %
// 16 of patch list[gl_VertexID / 16] (shaders/patchcull_draw_list.h, shipped_glsl("patchcull_draw_list.h"); the list
// stays bound at shared.h's kBindingDrawList after the pass, and the vertex shader must be allowed a storage block:
// GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS >= 1, which GL 4.5 does not promise). The patch index it finds is the flag
// buffer's index: pass it on (flat) as the flag path does.
//
// Buffers (the caller's; bound whole as std430 storage, so offsets need only be multiples of 4):
// - the flag range of PatchBuffers (control points and margins are not read: 0, or checked for size);
// - list, kBindingDrawList: uint entries; the range's survivors go to list[list_first ..
//   list_first + n), n <= count; the buffer must hold list_first + count entries (the worst case);
//   entries past n are left as they were;
// - command, kBindingDrawCommands: C = compact_command_count(count, K) DrawArraysIndirectCommands
//   from byte command_offset on, each written whole, K = DrawListBuffers::patches_per_command (0:
//   no limit, C = 1): command c is {16 m, 1, 16 (list_first + c K), 0} with m = min(K, n - c K)
//   when n > c K, else m = 0 (first = 16 entry, so gl_VertexID / 16 indexes the list itself). With
//   no limit that is the one command {16 n, 1, 16 list_first, 0}. A limit bounds the patches of
//   one draw command (llvmpipe's tessellation needs it: docs/ENGINE.md). Several ranges, e.g. one
//   per object, can share one list and one command buffer at different offsets;
// - draw count (optional), kBindingDrawCount: one uint at byte draw_count_offset, ceil(n / K) (with
//   no limit 1 when n > 0, else 0): glMultiDrawArraysIndirectCount's drawcount for these commands.
// State contract: gl_passes.h's, plus GL_COMMAND_BARRIER_BIT in the closing barrier (the indirect
// command and the draw count are visible to the draw). It binds the flag buffer at
// kBindingCullFlags, the list, command and count buffers at their bindings, and a buffer of its own
// at kBindingCompactSums (the survivor count between its steps, and for the prefix scan one uint
// per 2048 patches of the largest range seen before it; allocated on the first run and grown when
// a larger range comes: the only GL objects made after the first run). Fused: CullStatusPass::end
// with a DrawListBuffers (gl_passes.h) writes the same set, commands and count for the set the end
// decides, in the end's own dispatch (cull_status.comp.glsl's PC_STATUS_APPEND: one atomicAdd per
// work group, as the append) and a dispatch of this pass's commands step. Ranges of any size up to 2^28 patches
// (list_first + count < 2^28, so that 16 (list_first + count) fits in 32 bits) are covered by dispatches of at most
// 65535 work groups (the scan of a range of at most kCompactSingleGroupPatches: one dispatch); the flags up to
// first + count and the list up to list_first + count must fit GL_MAX_SHADER_STORAGE_BLOCK_SIZE (read once per
// PassContext; 128 MiB on llvmpipe: 2^25 patches).
// Errors: patchcull::Error with one line ("GL: CompactPass: ..."): a buffer that
// is not one or too small (the command buffer must hold C commands), an offset not a multiple of 4,
// a range past 2^28 or past the block size.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>

#include "patchcull/gl/gl_passes.h"

namespace patchcull::gl {

/// GL's DrawArraysIndirectCommand {count, instanceCount, first, baseInstance}, as CompactPass
/// writes it (for a read-back or a CPU-side draw).
struct DrawArraysIndirectCommand {
    std::uint32_t count = 0;           ///< vertices: 16 per surviving patch
    std::uint32_t instance_count = 0;  ///< 1
    std::uint32_t first = 0;           ///< 16 * list_first
    std::uint32_t base_instance = 0;   ///< 0
};
static_assert(sizeof(DrawArraysIndirectCommand) == 16);

/// How the list is built. All give the same set of patches and the same commands.
enum class CompactMethod {
    atomic_append,  ///< one atomicAdd per work group: the list's order may change from run to run
    prefix_scan,    ///< a prefix scan over work-group sums: ascending patch index, every run
    /// The atomic append fused into the chain's last stage (CullStatusPass::end with a
    /// DrawListBuffers, gl_passes.h) for the lists that stage decides: CullPipeline's pass 2 of a
    /// two-pass frame and the one-pass frame's draw (gl_pipeline.h); CompactPass::run itself
    /// treats it as atomic_append.
    fused_append,
};

/// "append", "scan" or "fused": the CLI's --compact values.
std::string_view compact_method_name(CompactMethod method);

/// The commands CompactPass writes for a range of count patches with at most patches_per_command
/// patches each (0: no limit): max(1, ceil(count / patches_per_command)), 1 without a limit. The
/// maxdrawcount of the range's draw.
std::size_t compact_command_count(std::size_t count, std::size_t patches_per_command);

/// Where CompactPass writes (GL buffer names and byte offsets; see the header).
struct DrawListBuffers {
    std::uint32_t list = 0;             ///< required: uint entries
    std::size_t list_first = 0;         ///< the range's first entry
    std::uint32_t command = 0;          ///< required: the DrawArraysIndirectCommand's buffer
    std::size_t command_offset = 0;     ///< bytes, a multiple of 4
    std::uint32_t draw_count = 0;       ///< optional (0: not written): the draw count's buffer
    std::size_t draw_count_offset = 0;  ///< bytes, a multiple of 4
    /// K: at most this many patches per command (0: no limit, one command); see the header.
    std::size_t patches_per_command = 0;
};

class CompactPass {
public:
    explicit CompactPass(PassContext& context);
    CompactPass(CompactPass&&) noexcept;
    CompactPass& operator=(CompactPass&&) noexcept;
    ~CompactPass();
    /// Writes the indices p in [patches.first, patches.first + patches.count) with
    /// (flags[p] & mask) == value (shared.h's kDrawMask* / kDrawValue* pairs; 0, 0 keeps every
    /// patch) to out.list, and the commands and draw count (see the header). A range of 0 patches
    /// writes the one command {0, 1, 16 list_first, 0} and draw count 0.
    void run(const PatchBuffers& patches, std::uint32_t mask, std::uint32_t value, const DrawListBuffers& out,
             CompactMethod method = CompactMethod::prefix_scan);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace patchcull::gl
