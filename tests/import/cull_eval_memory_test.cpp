// evaluate_cull's memory does not grow with the ground truth: the heap's high-water
// mark during a run over N patches stays within a few hundred bytes per patch (the batch, the
// displacement bounds, a decision byte) plus a fixed amount per thread, where the eager truth it
// replaced held N * 289 * (12 + 32) bytes of samples (12.7 KB per patch at grid 17) for the whole
// run. The heap is measured by counting every operator new and delete of this test program (this
// file replaces them; malloc_usable_size gives the sizes, under ASan too).
#include <gtest/gtest.h>

#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/parallel.h"
#include "patchcull/core/parallel_cull.h"
#include "patchcull/core/teapot.h"
#include "patchcull/eval/cull_eval.h"

namespace {

std::atomic<std::int64_t> g_live_bytes{0};
std::atomic<std::int64_t> g_peak_bytes{0};
std::atomic<std::int64_t> g_allocations{0};

void count_allocation(void* p) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
    const auto size = static_cast<std::int64_t>(malloc_usable_size(p));
    const std::int64_t live = g_live_bytes.fetch_add(size, std::memory_order_relaxed) + size;
    std::int64_t peak = g_peak_bytes.load(std::memory_order_relaxed);
    while (live > peak && !g_peak_bytes.compare_exchange_weak(peak, live, std::memory_order_relaxed)) {
    }
}

}  // namespace

void* operator new(std::size_t size) {
    void* p = std::malloc(size > 0 ? size : 1);
    if (!p) throw std::bad_alloc();
    count_allocation(p);
    return p;
}
void* operator new[](std::size_t size) { return ::operator new(size); }
void operator delete(void* p) noexcept {
    if (!p) return;
    g_live_bytes.fetch_sub(static_cast<std::int64_t>(malloc_usable_size(p)), std::memory_order_relaxed);
    std::free(p);
}
void operator delete[](void* p) noexcept { ::operator delete(p); }
void operator delete(void* p, std::size_t) noexcept { ::operator delete(p); }
void operator delete[](void* p, std::size_t) noexcept { ::operator delete(p); }

using namespace patchcull;

namespace {

// copies teapots (32 patches each) on a cubic lattice 4 units apart: N = 32 * copies patches,
// undisplaced, without tangent patches.
PatchFrame teapot_lattice(int copies) {
    const std::vector<BezierPatch> teapot = teapot_patches();
    PatchFrame frame;
    const int side = static_cast<int>(std::ceil(std::cbrt(double(copies))));
    for (int c = 0; c < copies; ++c) {
        const int x = c % side, y = (c / side) % side, z = c / (side * side);  // lattice cell
        const Vec4 offset{4.0f * float(x), 4.0f * float(y), 4.0f * float(z), 0};
        for (BezierPatch p : teapot) {
            for (Vec4& q : p.cp) q = q + offset;
            frame.patches.push_back(p);
        }
    }
    frame.info.resize(frame.patches.size());
    return frame;
}

}  // namespace

TEST(CullEvalMemory, PeakHeapGrowsByHundredsOfBytesPerPatchNotByTheSamples) {
    // 12,000 patches (187 full chunks of 64 and a partial one) up to 8 threads; more patches with
    // more threads, so that the per-thread scratch stays small beside the eager samples.
    const int threads = hardware_threads();
    const PatchFrame frame = teapot_lattice(375 * std::max(1, threads / 8));
    const std::int64_t n = static_cast<std::int64_t>(frame.patches.size());
    CullEvalOptions options;
    options.views = 2;
    options.mode = ViewMode::free;
    options.methods = {"frustum", "ptp"};  // both truths: surface samples and tangent planes
    const std::int64_t before = g_live_bytes.load();
    g_peak_bytes.store(before);
    const CullEvalResult r = evaluate_cull(frame, nullptr, options);
    const std::int64_t growth = g_peak_bytes.load() - before;
    // The batch is 64 floats a patch (256 bytes) padded to 16 patches; the rest is bytes per
    // patch. Each thread's window: 64 patches * 289 samples * 44 bytes (0.8 MB).
    const std::int64_t bound = 512 * n + std::int64_t{threads} * (1 << 20) + (4 << 20);
    const std::int64_t eager_samples = n * 289 * (12 + 32);
    std::printf(
        "[          ] peak heap growth %.1f MB for %lld patches (%.0f bytes a patch; bound %.1f MB; the eager "
        "samples alone %.1f MB)\n",
        growth / 1048576.0, static_cast<long long>(n), double(growth) / double(n), bound / 1048576.0,
        eager_samples / 1048576.0);
    EXPECT_LT(growth, bound);
    // The bound can fail: the eager truth's samples alone exceed it several times over.
    EXPECT_GT(eager_samples, 3 * bound);
    // The truth was consulted: both methods culled patches, and judged them all visible-free.
    ASSERT_EQ(r.methods.size(), 2u);
    for (const CullMethodResult& m : r.methods) {
        EXPECT_GT(m.culled, static_cast<std::uint64_t>(n) / 10) << m.name;
        EXPECT_EQ(m.false_culls, 0u) << m.name;
    }
}

// parallel_for_ranges takes its body by reference (RangeBody): a call with a lambda that captures
// more than a std::function keeps inline allocates nothing through operator new, and the ranges
// cover [0, count) once, starting at multiples of the grain.
TEST(ParallelForRanges, CoversEveryIndexOnceAndAllocatesNothing) {
    constexpr std::size_t kCount = 100003, kGrain = 64;
    std::vector<std::atomic<int>> hits(kCount);
    std::atomic<int> misaligned{0};
    const double a = 1, b = 2, c = 3, d = 4;  // captured by reference with hits: a large closure
    auto body = [&](std::size_t first, std::size_t last) {
        if (first % kGrain != 0) misaligned.fetch_add(1);
        for (std::size_t i = first; i < last; ++i) hits[i].fetch_add(static_cast<int>(a + b + c + d) - 9);
    };
    patchcull::parallel_for_ranges(kCount, kGrain, body);  // warm-up: oneTBB starts its workers
    for (auto& h : hits) h.store(0);
    const std::int64_t before = g_allocations.load();
    patchcull::parallel_for_ranges(kCount, kGrain, body);
    patchcull::parallel_for_ranges(kCount, kGrain, [&](std::size_t first, std::size_t last) { body(first, last); });
    const std::int64_t allocations = g_allocations.load() - before;
    EXPECT_EQ(allocations, 0);
    EXPECT_EQ(misaligned.load(), 0);
    for (std::size_t i = 0; i < kCount; ++i) ASSERT_EQ(hits[i].load(), 2) << i;
    patchcull::parallel_for_ranges(0, kGrain, body);  // nothing to do
    patchcull::parallel_for_ranges(5, 0, body);       // grain 0 counts as 1
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(hits[i].load(), 3) << i;
}

// The parallel kernel entries (parallel_cull.h) allocate nothing through operator new per call,
// warm oneTBB aside: every kernel over four ranges of a batch, into the caller's arrays.
TEST(ParallelCull, EntriesAllocateNothing) {
    using namespace patchcull;
    std::vector<BezierPatch> patches;
    const std::vector<BezierPatch> teapot = teapot_patches();
    for (std::size_t i = 0; patches.size() < 4 * kParallelGrain; ++i) {
        BezierPatch p = teapot[i % teapot.size()];
        for (Vec4& c : p.cp) c.x += 3.0f * static_cast<float>(i / teapot.size() % 9) - 12.0f;
        patches.push_back(p);
    }
    const PatchBatch batch = make_batch(patches);
    Camera cam;
    cam.eye = {0, -10, 2};
    cam.target = {0, 0, 1};
    cam.up = {0, 0, 1};
    const CullView view = make_cull_view(cam.view(), cam.projection(), cam.depth, cam.eye);
    std::vector<float> depth(64 * 64, 1.0f);
    HiZPyramid hiz;
    hiz.build(depth.data(), 64, 64, cam.depth);
    const FusedCullSetup setup = make_fused_setup(view, BackPatchCone::tcone, &hiz);
    std::vector<std::uint8_t> out(batch.size());
    std::size_t culled = 0;
    auto run_all = [&] {
        cull_frustum_parallel(batch.view(), nullptr, view, out.data());
        cull_frustum_disp_parallel(batch.view(), nullptr, view, out.data());
        for (BackpatchMethod id : {BackpatchMethod::tcone, BackpatchMethod::ncone, BackpatchMethod::ptp}) {
            cull_backpatch_parallel(id, batch.view(), view, {}, out.data());
            for (std::uint8_t c : out) culled += c != 0;
        }
        cull_occlusion_parallel(batch.view(), view, hiz, out.data());
        cull_fused_parallel(batch.view(), setup, FusedPlan{}, out.data());
    };
    run_all();  // warm-up: oneTBB starts its workers
    culled = 0;
    const std::int64_t before = g_allocations.load();
    run_all();
    EXPECT_EQ(g_allocations.load() - before, 0);
    EXPECT_GT(culled, 0u);  // the kernels ran over real work
}
