// The timing loop shared by the cull-kernel benchmarks (frustum, tcone/ncone, ptp): runs a kernel
// over n patches per iteration, on one thread or split into kBenchGrain-patch ranges over every
// core (parallel.h), optionally with Highway forced to one SIMD target, and reports patches/s,
// the culled fraction and the kernel's label.
#pragma once

#include <benchmark/benchmark.h>
#include <hwy/targets.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "patchcull/core/parallel.h"

namespace patchcull::bench {

inline constexpr std::size_t kBenchGrain = 1024;  // patches per parallel range

/// run_range(first, last) culls patches [first, last) into culled[first, last). forced_target:
/// 0 = normal dispatch, else a Highway target bit (e.g. HWY_AVX2) to compare vector widths; the
/// benchmark is skipped when the CPU lacks it. label: shown by Google Benchmark (e.g. the
/// dispatched target's name), read after the runs so a forced target is named.
template <class RunRange, class Label>
void run_cull_benchmark(benchmark::State& state, std::size_t n, std::uint8_t* culled, bool all_threads,
                        std::int64_t forced_target, const RunRange& run_range, const Label& label) {
    if (forced_target != 0) {
        if ((hwy::SupportedTargets() & forced_target) == 0) {
            state.SkipWithError("target not supported on this CPU");
            return;
        }
        hwy::SetSupportedTargetsForTest(forced_target);
    }
    for (auto _ : state) {
        if (all_threads) {
            parallel_for_ranges(n, kBenchGrain, [&](std::size_t a, std::size_t b) { run_range(a, b); });
        } else {
            run_range(0, n);
        }
        benchmark::DoNotOptimize(culled);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
    std::size_t c = 0;
    for (std::size_t i = 0; i < n; ++i) c += culled[i];
    state.counters["culled"] = static_cast<double>(c) / static_cast<double>(n);
    state.counters["threads"] = all_threads ? hardware_threads() : 1;
    state.SetLabel(std::string(label()));
    if (forced_target != 0) hwy::SetSupportedTargetsForTest(0);
}

}  // namespace patchcull::bench
