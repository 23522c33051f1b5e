// Benchmarks of the parametric tangent plane back-patch kernel (patchcull/core/backpatch.h,
// Loop, Niessner & Eisenacher §3-6): scalar reference vs SIMD (dispatched target, and forced to
// 8-lane AVX2), one thread vs all threads (parallel_for_ranges, grain 1024), for 11532 patches
// (the killeroo's count in Loop, Niessner & Eisenacher) and 65536. items_per_second is patches per second.
//
// Workload: random curved bicubic sheets (0.2..1.0 across) with centres uniform in a box around a
// perspective view (the frustum benchmark's generator), each patch facing a random direction, so
// about half are culled. The kernel's cost does not depend on the data (no early exit).
//
// Run (see docs/PERFORMANCE.md):
//   build-ptp/bench/patchcull_bench --benchmark_filter='ptp|cpu_clock'
//       --benchmark_repetitions=3 --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <hwy/targets.h>

#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "cull_bench_loop.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/parallel.h"
#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

struct PtpWorkload {
    PatchBatch batch;
    Mat4 object_to_clip;
    float alpha = 0;
    std::vector<std::uint8_t> culled;
};

PtpWorkload& ptp_workload(std::size_t n, bool rational) {
    static std::map<std::pair<std::size_t, bool>, std::unique_ptr<PtpWorkload>> cache;
    auto& slot = cache[{n, rational}];
    if (slot) return *slot;
    slot = std::make_unique<PtpWorkload>();
    PtpWorkload& w = *slot;
    std::mt19937 rng(static_cast<unsigned>(n) * 2 + rational + 1001);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    std::vector<BezierPatch> patches(n);
    for (std::size_t p = 0; p < n; ++p) {
        const Vec3 c{30 * u(rng), 12 * u(rng), 30 * u(rng) - 10};
        const float size = 0.2f + 0.8f * unit(rng);
        const Vec3 a = Vec3{u(rng), u(rng), u(rng)} * size, b = Vec3{u(rng), u(rng), u(rng)} * size;
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const Vec3 pt = c + a * (i / 3.0f - 0.5f) + b * (j / 3.0f - 0.5f) + Vec3{0, 0.2f * size * u(rng), 0};
                patches[p].cp[4 * j + i] = homogeneous(pt, rational ? 0.5f + 1.5f * unit(rng) : 1.0f);
            }
    }
    w.batch = make_batch(patches);
    const Mat4 proj = perspective(60.0f * 3.14159265f / 180, 16.0f / 9.0f, 0.1f, 200.0f);
    w.object_to_clip = proj * look_at({0, 3, 15}, {0, 0, 0}, {0, 1, 0});
    w.alpha = clip_space_eye_alpha(proj);
    w.culled.assign(n, 0);
    return w;
}

enum class PtpImpl { kScalar, kSimd };

void run_ptp_range(const PtpWorkload& w, PtpImpl impl, PtpRule rule, std::size_t first, std::size_t last,
                   std::uint8_t* culled) {
    const PatchBatchView v = w.batch.view().subrange(first, last - first);
    (impl == PtpImpl::kSimd ? cull_ptp_simd : cull_ptp_scalar)(v, w.object_to_clip, w.alpha, rule, culled + first);
}

void bm_ptp(benchmark::State& state, PtpImpl impl, bool all_threads, PtpRule rule, bool rational,
            std::int64_t forced_target) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    PtpWorkload& w = ptp_workload(n, rational);
    std::uint8_t* culled = w.culled.data();
    bench::run_cull_benchmark(
        state, n, culled, all_threads, forced_target,
        [&](std::size_t a, std::size_t b) { run_ptp_range(w, impl, rule, a, b, culled); },
        [&] { return impl == PtpImpl::kSimd ? simd_target_name() : "scalar"; });
}

int register_ptp() {
    const std::vector<std::int64_t> sizes = {11532, 65536};
    for (PtpImpl impl : {PtpImpl::kScalar, PtpImpl::kSimd})
        for (bool mt : {false, true}) {
            const std::string name = std::string("ptp/") + (impl == PtpImpl::kSimd ? "simd" : "scalar") + "/" +
                                     (mt ? "all_threads" : "1_thread");
            auto* b = benchmark::RegisterBenchmark(
                name.c_str(), [=](benchmark::State& s) { bm_ptp(s, impl, mt, PtpRule::ncnt, false, 0); });
            for (std::int64_t n : sizes) b->Arg(n);
            b->UseRealTime()->Unit(benchmark::kMicrosecond);
        }
    benchmark::RegisterBenchmark(
        "ptp/simd_avx2/1_thread",
        [](benchmark::State& s) { bm_ptp(s, PtpImpl::kSimd, false, PtpRule::ncnt, false, HWY_AVX2); })
        ->Arg(11532)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark("ptp_pcnt/simd/1_thread",
                                 [](benchmark::State& s) { bm_ptp(s, PtpImpl::kSimd, false, PtpRule::pcnt, false, 0); })
        ->Arg(11532)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark("ptp_rational/simd/1_thread",
                                 [](benchmark::State& s) { bm_ptp(s, PtpImpl::kSimd, false, PtpRule::ncnt, true, 0); })
        ->Arg(11532)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    return 0;
}

[[maybe_unused]] const int ptp_registered = register_ptp();

}  // namespace
