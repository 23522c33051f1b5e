// patchcull/core/parallel_cull.h: the cull kernels on every core: the same decisions as the
// single-threaded SIMD entries, byte for byte.
//
// Each entry splits [0, patches.count) into ranges that start at whole blocks (kBlockPatches: a
// blocked view splits between blocks, a plain view keeps its aligned SIMD loads), one per thread of
// the calling task arena for small batches and kParallelGrain patches each for large ones, and runs
// the single-threaded kernel on each through parallel_for_ranges (parallel.h): on the calling
// thread and the oneTBB workers of its arena, so an engine bounds or places the threads by calling
// from inside its own tbb::task_arena. Nothing is allocated per call beyond oneTBB's pooled task
// objects (tested), and the outputs are the caller's arrays. Where two threads stop paying, below
// which an entry runs on the calling thread alone (docs/PERFORMANCE.md, "2-core scaling"): 1,024
// patches for the frustum kernels, 512 for occlusion, 256 for the back-patch and fused kernels.
//
// Over a PatchSourceView (patch_source.h: the caller's own points, e.g. an OpenSubdiv patch table's
// arrays) the entries split [0, source.count) the same way and run the patch-source entry's work
// on each range (its 4 KiB stack block per thread, nothing else allocated): the same decisions as
// the single-threaded patch-source entry, byte for byte.
//
// Errors: the same as the single-threaded entry's, checked once before any range runs.
#pragma once

#include <cstddef>
#include <cstdint>

#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/patch_source.h"

namespace patchcull {

/// The largest range of the parallel entries, in patches (256 blocks: 1 MiB of control points).
inline constexpr std::size_t kParallelGrain = 4096;
static_assert(kParallelGrain % kBlockPatches == 0, "ranges must start at a block");

/// cull_frustum (frustum.h) on every core; max_displacement null or patches.count values.
void cull_frustum_parallel(const PatchBatchView& patches, const float* max_displacement, const CullView& view,
                           std::uint8_t* culled);
/// cull_frustum_disp (frustum.h) on every core.
void cull_frustum_disp_parallel(const PatchBatchView& patches, const float* max_displacement, const CullView& view,
                                std::uint8_t* culled);
/// cull_backpatch (backpatch_methods.h) on every core: method id's SIMD kernel (or scalar).
void cull_backpatch_parallel(BackpatchMethod id, const PatchBatchView& patches, const CullView& view,
                             const BackpatchOptions& options, std::uint8_t* culled);
/// cull_occlusion (hiz.h) on every core; hiz is read-only and shared by the threads.
void cull_occlusion_parallel(const PatchBatchView& patches, const CullView& view, const HiZPyramid& hiz,
                             std::uint8_t* decision);
/// cull_fused_simd (fused_cull.h) on every core; throws Error for a plan valid_fused_plan refuses.
/// Takes no FusedCullStats: the counts would be a shared write per group (profile single-threaded).
void cull_fused_parallel(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
                         std::uint8_t* decision);

/// The patch-source entries (patch_source.h: cull_frustum, cull_frustum_disp, cull_backpatch,
/// cull_occlusion, cull_fused over a PatchSourceView) on every core, with their checks (the view
/// once, the plan and pyramid for cull_fused_parallel) before any range runs.
void cull_frustum_parallel(const PatchSourceView& source, const float* max_displacement, const CullView& view,
                           std::uint8_t* culled);
void cull_frustum_disp_parallel(const PatchSourceView& source, const float* max_displacement, const CullView& view,
                                std::uint8_t* culled);
void cull_backpatch_parallel(BackpatchMethod id, const PatchSourceView& source, const CullView& view,
                             const BackpatchOptions& options, std::uint8_t* culled);
void cull_occlusion_parallel(const PatchSourceView& source, const CullView& view, const HiZPyramid& hiz,
                             std::uint8_t* decision);
void cull_fused_parallel(const PatchSourceView& source, const FusedCullSetup& setup, const FusedPlan& plan,
                         std::uint8_t* decision);

}  // namespace patchcull
