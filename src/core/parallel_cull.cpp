// The kernels over parallel_for_ranges (patchcull/core/parallel_cull.h).
#include "patchcull/core/parallel_cull.h"

#include <algorithm>

#include <tbb/task_arena.h>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/parallel.h"

namespace patchcull {
namespace {

// Below these counts one thread is faster: the smallest sizes from which two threads stayed >= 1.1x
// one in docs/PERFORMANCE.md's 2-core scaling run (frustum kernels 1024, occlusion 512, the
// compute-bound back-patch and fused kernels 256, the smallest size measured).
constexpr std::size_t kFrustumMinPatches = 1024;
constexpr std::size_t kOcclusionMinPatches = 512;
constexpr std::size_t kComputeBoundMinPatches = 256;

// Runs kernel(range view, first) over ranges of patches: one per thread of the calling arena for
// small batches (rounded up to whole blocks), kParallelGrain patches each for large ones.
template <class Kernel>
void for_each_range(const PatchBatchView& patches, std::size_t min_patches, const Kernel& kernel) {
    const std::size_t threads = static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
    if (patches.count < min_patches || threads == 1) {
        kernel(patches, std::size_t{0});
        return;
    }
    const std::size_t per_thread = (patches.count + threads - 1) / threads;
    const std::size_t grain =
        std::min(kParallelGrain, (per_thread + kBlockPatches - 1) / kBlockPatches * kBlockPatches);
    parallel_for_ranges(patches.count, grain, [&](std::size_t first, std::size_t last) {
        kernel(patches.subrange(first, last - first), first);
    });
}

const float* offset(const float* values, std::size_t first) { return values ? values + first : nullptr; }

}  // namespace

void cull_frustum_parallel(const PatchBatchView& patches, const float* max_displacement, const CullView& view,
                           std::uint8_t* culled) {
    for_each_range(patches, kFrustumMinPatches, [&](const PatchBatchView& range, std::size_t first) {
        cull_frustum(range, offset(max_displacement, first), view, culled + first);
    });
}

void cull_frustum_disp_parallel(const PatchBatchView& patches, const float* max_displacement, const CullView& view,
                                std::uint8_t* culled) {
    check_clip_depth(view.object_to_clip, view.depth, "cull_frustum_disp_parallel");
    for_each_range(patches, kFrustumMinPatches, [&](const PatchBatchView& range, std::size_t first) {
        cull_frustum_disp(range, offset(max_displacement, first), view, culled + first);
    });
}

void cull_backpatch_parallel(BackpatchMethod id, const PatchBatchView& patches, const CullView& view,
                             const BackpatchOptions& options, std::uint8_t* culled) {
    backpatch_method_info(id);  // Error for an unknown id, before any thread starts
    for_each_range(patches, kComputeBoundMinPatches, [&](const PatchBatchView& range, std::size_t first) {
        cull_backpatch(id, range, view, options, culled + first);
    });
}

void cull_occlusion_parallel(const PatchBatchView& patches, const CullView& view, const HiZPyramid& hiz,
                             std::uint8_t* decision) {
    check_clip_depth(view.object_to_clip, view.depth, "cull_occlusion_parallel");
    check_hiz_convention(hiz, view.depth, "cull_occlusion_parallel");
    for_each_range(patches, kOcclusionMinPatches, [&](const PatchBatchView& range, std::size_t first) {
        cull_occlusion(range, view, hiz, decision + first);
    });
}

void cull_fused_parallel(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
                         std::uint8_t* decision) {
    if (!valid_fused_plan(plan)) throw Error("cull_fused_parallel: invalid plan " + fused_plan_name(plan));
    for_each_range(patches, kComputeBoundMinPatches, [&](const PatchBatchView& range, std::size_t first) {
        cull_fused_simd(range, setup, plan, decision + first);
    });
}

}  // namespace patchcull
