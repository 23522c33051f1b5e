// Benchmarks of the cone back-patch kernels (patchcull/core/backpatch.h): tcone and ncone, scalar
// reference vs SIMD (dispatched target), one thread vs all threads (parallel_for_ranges, grain
// 1024), on 11532 (the killeroo's patch count in Loop, Niessner & Eisenacher) and 65536 random
// patches: gently curved sheets of random size and orientation around the eye, ~1/3 of them
// back-facing enough to be culled. items_per_second is patches per second; the `culled` counter
// is the cull rate.
//
// Run (see docs/PERFORMANCE.md, "CPU back-patch kernels: tcone, ncone"):
//   build-cones/bench/patchcull_bench --benchmark_filter='^(tcone|ncone)|cpu_clock'
//       --benchmark_repetitions=3 --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "cull_bench_loop.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/frustum.h"  // simd_target_name
#include "patchcull/core/parallel.h"
#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

struct ConeWorkload {
    PatchBatch batch;
    Vec3 eye{0, 0, 0};
    std::vector<std::uint8_t> culled;
};

// n sheets: a random frame, a 4x4 grid with small jitter and a bend of relative height 0.001..0.3,
// 0.2..1 across, centres 2..30 units from the eye (at the origin) in random directions.
ConeWorkload& cone_workload(std::size_t n) {
    static std::map<std::size_t, std::unique_ptr<ConeWorkload>> cache;
    auto& slot = cache[n];
    if (slot) return *slot;
    slot = std::make_unique<ConeWorkload>();
    ConeWorkload& w = *slot;
    std::mt19937 rng(static_cast<unsigned>(n) + 7);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    auto random_unit = [&]() {
        for (;;) {
            const Vec3 v{u(rng), u(rng), u(rng)};
            const float l = length(v);
            if (l > 0.1f && l <= 1) return v * (1 / l);
        }
    };
    std::vector<BezierPatch> patches(n);
    for (auto& patch : patches) {
        const Vec3 nrm = random_unit();
        const Vec3 t = normalize(cross(nrm, random_unit())), b = cross(nrm, t);
        const Vec3 c = random_unit() * (2 + 28 * unit(rng));
        const float size = 0.2f + 0.8f * unit(rng);
        const float bump = std::pow(10.0f, -3 + 2.5f * unit(rng));
        const float bu = bump * u(rng), bv = bump * u(rng);
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const float x = i / 3.0f - 0.5f + 0.02f * u(rng), y = j / 3.0f - 0.5f + 0.02f * u(rng);
                const float h = bump * 0.3f * u(rng) + bu * x * x + bv * y * y;
                patch.cp[4 * j + i] = homogeneous(c + (t * x + b * y + nrm * h) * size);
            }
    }
    w.batch = make_batch(patches);
    w.culled.assign(n, 0);
    return w;
}

enum class Kernel { kTcone, kNcone };
enum class Impl { kScalar, kSimd };

void run_range(const ConeWorkload& w, Kernel k, Impl impl, std::size_t first, std::size_t last, std::uint8_t* culled) {
    const PatchBatchView v = w.batch.view().subrange(first, last - first);
    if (k == Kernel::kTcone) {
        (impl == Impl::kSimd ? cull_tcone_simd : cull_tcone_scalar)(v, w.eye, culled + first);
    } else {
        (impl == Impl::kSimd ? cull_ncone_simd : cull_ncone_scalar)(v, w.eye, culled + first);
    }
}

void bm_cone(benchmark::State& state, Kernel k, Impl impl, bool all_threads) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    ConeWorkload& w = cone_workload(n);
    std::uint8_t* culled = w.culled.data();
    bench::run_cull_benchmark(
        state, n, culled, all_threads, 0, [&](std::size_t a, std::size_t b) { run_range(w, k, impl, a, b, culled); },
        [&] { return impl == Impl::kSimd ? simd_target_name() : "scalar"; });
}

int register_cones() {
    for (Kernel k : {Kernel::kTcone, Kernel::kNcone})
        for (Impl impl : {Impl::kScalar, Impl::kSimd})
            for (bool mt : {false, true}) {
                const std::string name = std::string(k == Kernel::kTcone ? "tcone" : "ncone") + "/" +
                                         (impl == Impl::kSimd ? "simd" : "scalar") + "/" +
                                         (mt ? "all_threads" : "1_thread");
                benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& s) { bm_cone(s, k, impl, mt); })
                    ->Arg(11532)
                    ->Arg(65536)
                    ->UseRealTime()
                    ->Unit(benchmark::kMicrosecond);
            }
    return 0;
}

[[maybe_unused]] const int cones_registered = register_cones();

}  // namespace
