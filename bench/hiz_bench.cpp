// Benchmarks of the Hi-Z pyramid and the occlusion test (patchcull/core/hiz.h).
//
// hiz_build/WxH: HiZPyramid::build from a W x H float depth buffer (storage allocated before the
//   timed loop; one thread). items_per_second = depth pixels/s, bytes_per_second = depth bytes read.
// hiz_occlusion_{scalar,simd}[_mt]/N: cull_occlusion_* on N random patches (the frustum benchmark's
//   distribution) against a 1920x1080 pyramid of a synthetic occluder layer (random screen
//   rectangles at distances 8-20, background far); _mt runs parallel_for_ranges (grain 1024) over
//   all threads. items_per_second = patches/s. Counters: fractions occluded / frustum-culled.
//   *_2x2screen: the same patches against a 2x2 screen (diagnostic: the texel loads then always hit
//   the same cache line, so the difference to the 1920x1080 rows is the cost of steps 7-9).
//
// Run (see docs/PERFORMANCE.md):
//   build-hiz/bench/patchcull_bench --benchmark_filter='hiz_' --benchmark_repetitions=3
//       --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "patchcull/core/hiz.h"
#include "patchcull/core/parallel.h"
#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

constexpr std::size_t kHiZGrain = 1024;

std::vector<float> synthetic_depth(int W, int H, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0, 1);
    std::vector<float> depth(static_cast<std::size_t>(W) * H, 1.0f);
    // Depth z/w at view distance d for perspective(..., 0.1, 200) (math.cpp, GL_ZERO_TO_ONE).
    const float n = 0.1f, f = 200.0f;
    auto depth_at = [&](float d) { return (f / (f - n)) * (1 - n / d); };  // GL_ZERO_TO_ONE perspective
    for (int r = 0; r < 60; ++r) {
        const int x0 = static_cast<int>(unit(rng) * W), y0 = static_cast<int>(unit(rng) * H);
        const int w = 1 + static_cast<int>(unit(rng) * W * 0.3f), h = 1 + static_cast<int>(unit(rng) * H * 0.3f);
        const float z = depth_at(8 + 12 * unit(rng));
        for (int y = y0; y < std::min(H, y0 + h); ++y)
            for (int x = x0; x < std::min(W, x0 + w); ++x) {
                float& d = depth[static_cast<std::size_t>(y) * W + x];
                d = std::min(d, z);
            }
    }
    return depth;
}

void bm_build(benchmark::State& state) {
    const int W = static_cast<int>(state.range(0)), H = static_cast<int>(state.range(1));
    const std::vector<float> depth = synthetic_depth(W, H, 1);
    HiZPyramid hiz(W, H);
    for (auto _ : state) {
        hiz.build(depth.data(), W, H);
        benchmark::DoNotOptimize(hiz.data());
        benchmark::ClobberMemory();
    }
    const std::int64_t pixels = static_cast<std::int64_t>(W) * H;
    state.SetItemsProcessed(state.iterations() * pixels);
    state.SetBytesProcessed(state.iterations() * pixels * static_cast<std::int64_t>(sizeof(float)));
    state.counters["levels"] = hiz.levels();
}

struct OcclusionWorkload {
    PatchBatch batch;
    Mat4 object_to_clip;
    HiZPyramid hiz;
    HiZPyramid tiny;  // 2x2 screen: the texel loads always hit one cache line (isolates steps 1-6)
    std::vector<std::uint8_t> decision;
};

OcclusionWorkload& occlusion_workload(std::size_t n) {
    static std::map<std::size_t, std::unique_ptr<OcclusionWorkload>> cache;
    auto& slot = cache[n];
    if (slot) return *slot;
    slot = std::make_unique<OcclusionWorkload>();
    OcclusionWorkload& w = *slot;
    std::mt19937 rng(static_cast<unsigned>(n) * 2);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    std::vector<BezierPatch> patches(n);
    for (std::size_t p = 0; p < n; ++p) {  // same distribution as frustum_bench.cpp
        const Vec3 c{30 * u(rng), 12 * u(rng), 30 * u(rng) - 10};
        const float size = 0.2f + 0.8f * unit(rng);
        const Vec3 a = Vec3{u(rng), u(rng), u(rng)} * size, b = Vec3{u(rng), u(rng), u(rng)} * size;
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const Vec3 pt = c + a * (i / 3.0f - 0.5f) + b * (j / 3.0f - 0.5f) + Vec3{0, 0.2f * size * u(rng), 0};
                patches[p].cp[4 * j + i] = homogeneous(pt, 1.0f);
            }
    }
    w.batch = make_batch(patches);
    w.object_to_clip =
        perspective(60.0f * 3.14159265f / 180, 16.0f / 9.0f, 0.1f, 200.0f) * look_at({0, 3, 15}, {0, 0, 0}, {0, 1, 0});
    const int W = 1920, H = 1080;
    const std::vector<float> depth = synthetic_depth(W, H, 7);
    w.hiz.build(depth.data(), W, H);
    const float tiny_depth[4] = {0.5f, 0.5f, 0.5f, 0.5f};
    w.tiny.build(tiny_depth, 2, 2);
    w.decision.assign(n, 0);
    return w;
}

void bm_occlusion(benchmark::State& state, bool simd, bool all_threads, bool tiny) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    OcclusionWorkload& w = occlusion_workload(n);
    auto kernel = simd ? cull_occlusion_simd : cull_occlusion_scalar;
    std::uint8_t* out = w.decision.data();
    const HiZPyramid& hiz = tiny ? w.tiny : w.hiz;
    for (auto _ : state) {
        if (all_threads) {
            parallel_for_ranges(n, kHiZGrain, [&](std::size_t a, std::size_t b) {
                kernel(w.batch.view().subrange(a, b - a), w.object_to_clip, ClipDepth::zero_to_one, hiz, out + a);
            });
        } else {
            kernel(w.batch.view(), w.object_to_clip, ClipDepth::zero_to_one, hiz, out);
        }
        benchmark::DoNotOptimize(out);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
    std::size_t occ = 0, fr = 0;
    for (std::size_t i = 0; i < n; ++i) {
        occ += out[i] == kHiZOccluded;
        fr += out[i] == kHiZFrustumCulled;
    }
    state.counters["occluded"] = static_cast<double>(occ) / static_cast<double>(n);
    state.counters["frustum"] = static_cast<double>(fr) / static_cast<double>(n);
    state.counters["threads"] = all_threads ? hardware_threads() : 1;
}

int register_hiz() {
    for (auto [W, H] : {std::pair{256, 256}, {1024, 1024}, {1920, 1080}, {4096, 4096}})
        benchmark::RegisterBenchmark("hiz_build", bm_build)->Args({W, H})->Unit(benchmark::kMicrosecond);
    for (std::int64_t n : {5168, 65536}) {
        benchmark::RegisterBenchmark("hiz_occlusion_scalar", bm_occlusion, false, false, false)->Arg(n);
        benchmark::RegisterBenchmark("hiz_occlusion_scalar_mt", bm_occlusion, false, true, false)
            ->Arg(n)
            ->UseRealTime();
        benchmark::RegisterBenchmark("hiz_occlusion_simd", bm_occlusion, true, false, false)->Arg(n);
        benchmark::RegisterBenchmark("hiz_occlusion_simd_mt", bm_occlusion, true, true, false)->Arg(n)->UseRealTime();
        benchmark::RegisterBenchmark("hiz_occlusion_simd_2x2screen", bm_occlusion, true, false, true)->Arg(n);
        benchmark::RegisterBenchmark("hiz_occlusion_scalar_2x2screen", bm_occlusion, false, false, true)->Arg(n);
    }
    return 0;
}

const int kRegisteredHiZ = register_hiz();

}  // namespace
