// The kernels over parallel_for_ranges (patchcull/core/parallel_cull.h).
#include "patchcull/core/parallel_cull.h"

#include <algorithm>

#include <tbb/task_arena.h>

#include "core/patch_source_internal.h"
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

// Runs body(first, last) over ranges of [0, count): one per thread of the calling arena for small
// counts (rounded up to whole blocks), kParallelGrain patches each for large ones.
template <class Body>
void for_each_index_range(std::size_t count, std::size_t min_patches, const Body& body) {
    const std::size_t threads = static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
    if (count < min_patches || threads == 1) {
        body(std::size_t{0}, count);
        return;
    }
    const std::size_t per_thread = (count + threads - 1) / threads;
    const std::size_t grain =
        std::min(kParallelGrain, (per_thread + kBlockPatches - 1) / kBlockPatches * kBlockPatches);
    parallel_for_ranges(count, grain, body);
}

// Runs kernel(range view, first) over ranges of patches (for_each_index_range's).
template <class Kernel>
void for_each_range(const PatchBatchView& patches, std::size_t min_patches, const Kernel& kernel) {
    for_each_index_range(patches.count, min_patches, [&](std::size_t first, std::size_t last) {
        kernel(first == 0 && last == patches.count ? patches : patches.subrange(first, last - first), first);
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

// ---- Over a PatchSourceView: the checks once, then the unchecked range entries per range. -------

void cull_frustum_parallel(const PatchSourceView& source, const float* max_displacement, const CullView& view,
                           std::uint8_t* culled) {
    check_patch_source(source, "cull_frustum_parallel");
    for_each_index_range(source.count, kFrustumMinPatches, [&](std::size_t first, std::size_t last) {
        detail::source_frustum(source, first, last, max_displacement, view.planes, culled);
    });
}

void cull_frustum_disp_parallel(const PatchSourceView& source, const float* max_displacement, const CullView& view,
                                std::uint8_t* culled) {
    check_patch_source(source, "cull_frustum_disp_parallel");
    const FrustumPlanes planes = make_frustum_planes(view.object_to_clip, view.depth);  // refuses a contradiction
    for_each_index_range(source.count, kFrustumMinPatches, [&](std::size_t first, std::size_t last) {
        detail::source_frustum_disp(source, first, last, max_displacement, planes, culled);
    });
}

void cull_backpatch_parallel(BackpatchMethod id, const PatchSourceView& source, const CullView& view,
                             const BackpatchOptions& options, std::uint8_t* culled) {
    check_patch_source(source, "cull_backpatch_parallel");
    const BackpatchMethodInfo& method = backpatch_method_info(id);  // Error for an unknown id
    for_each_index_range(source.count, kComputeBoundMinPatches, [&](std::size_t first, std::size_t last) {
        detail::source_backpatch(method, source, first, last, view, options, culled);
    });
}

void cull_occlusion_parallel(const PatchSourceView& source, const CullView& view, const HiZPyramid& hiz,
                             std::uint8_t* decision) {
    check_patch_source(source, "cull_occlusion_parallel");
    check_hiz_convention(hiz, view.depth, "cull_occlusion_parallel");
    const FusedCullSetup setup = make_fused_setup(view, BackPatchCone::tcone, &hiz);
    FusedPlan plan;  // cull_occlusion's: frustum, then Hi-Z
    plan.stages[0] = FusedStage::frustum;
    plan.stages[1] = FusedStage::occlusion;
    plan.count = 2;
    for_each_index_range(source.count, kOcclusionMinPatches, [&](std::size_t first, std::size_t last) {
        detail::source_fused(source, first, last, setup, plan, decision, nullptr);
    });
}

void cull_fused_parallel(const PatchSourceView& source, const FusedCullSetup& setup, const FusedPlan& plan,
                         std::uint8_t* decision) {
    check_patch_source(source, "cull_fused_parallel");
    detail::check_fused_inputs(setup, plan, "cull_fused_parallel");
    for_each_index_range(source.count, kComputeBoundMinPatches, [&](std::size_t first, std::size_t last) {
        detail::source_fused(source, first, last, setup, plan, decision, nullptr);
    });
}

}  // namespace patchcull
