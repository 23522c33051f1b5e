// Benchmarks of the per-patch displacement range (patchcull/core/displacement.h).
//
// displacement_range_{exact,pyramid}/S/F: DisplacementMap::patch_range_exact (the texel scan) and
//   patch_range (the min/max pyramid) on an S x S map of random heights, for 1024 patches whose
//   texture footprints are axis-aligned squares of F texels a side at random positions (wrapping
//   around the map). The pyramid is built before the timed loop (its build is
//   displacement_pyramid_build/S). items_per_second = patches/s.
//
// Run (see docs/PERFORMANCE.md):
//   build-pre/bench/patchcull_bench --benchmark_filter='displacement_' --benchmark_repetitions=3
//       --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "patchcull/core/displacement.h"

using namespace patchcull;

namespace {

DisplacementMap random_map(int size) {
    DisplacementMap m;
    m.width = m.height = size;
    m.scale = 1.0f;
    m.texels.resize(static_cast<std::size_t>(size) * size);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> unit(0, 1);
    for (float& t : m.texels) t = unit(rng);
    return m;
}

std::vector<std::array<Vec2, 4>> footprints(int size, int texels, int count) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> unit(0, 1);
    std::vector<std::array<Vec2, 4>> out(static_cast<std::size_t>(count));
    const float side = static_cast<float>(texels) / static_cast<float>(size);
    for (auto& uv : out) {
        const Vec2 base{unit(rng), unit(rng)};
        for (int k = 0; k < 4; ++k) uv[k] = base + Vec2{(k & 1) * side, (k >> 1) * side};
    }
    return out;
}

template <bool kPyramid>
void range_bench(benchmark::State& state) {
    const int size = static_cast<int>(state.range(0)), texels = static_cast<int>(state.range(1));
    const DisplacementMap map = random_map(size);
    const auto uvs = footprints(size, texels, 1024);
    benchmark::DoNotOptimize(map.patch_range(uvs[0].data()));  // builds the pyramid
    for (auto _ : state)
        for (const auto& uv : uvs) {
            const DisplacementRange r = kPyramid ? map.patch_range(uv.data()) : map.patch_range_exact(uv.data());
            benchmark::DoNotOptimize(r);
        }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(uvs.size()));
}

void displacement_range_exact(benchmark::State& state) { range_bench<false>(state); }
void displacement_range_pyramid(benchmark::State& state) { range_bench<true>(state); }

void displacement_pyramid_build(benchmark::State& state) {
    const int size = static_cast<int>(state.range(0));
    DisplacementMap map = random_map(size);
    const Vec2 uv[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    for (auto _ : state) {
        map.texels_changed();
        benchmark::DoNotOptimize(map.patch_range(uv));
    }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(map.texels.size()));
}

}  // namespace

BENCHMARK(displacement_range_exact)->Args({1024, 1})->Args({1024, 16})->Args({1024, 256})->Args({1024, 1024});
BENCHMARK(displacement_range_pyramid)->Args({1024, 1})->Args({1024, 16})->Args({1024, 256})->Args({1024, 1024});
BENCHMARK(displacement_pyramid_build)->Arg(1024)->Arg(4096)->Unit(benchmark::kMillisecond);
