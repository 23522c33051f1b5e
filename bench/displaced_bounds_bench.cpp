// Benchmarks of the displaced-patch bounds (patchcull/core/displaced_bounds.h): the six combinations
// {oobb, caf} x {full, acon, con}, scalar, one thread, as the frustum kernel (cull_displaced_frustum)
// and as the frustum + Hi-Z occlusion kernel (cull_displaced_occlusion, 1920x1080 pyramid).
// items_per_second is patches per second. Niessner & Loop, Fig. 7 expects NoDisp, Full and ACoN
// at about the same cost and CoN about ten times slower; two NoDisp references are included:
//   displaced_occlusion/nodisp_caf: the CAF kernel with null ranges (no cone is computed);
//   displaced_occlusion/nodisp_hiz: hiz.h's cull_occlusion_scalar (control-point NDC box, no
//   view-space bound), the kernel for undisplaced patches.
//
// Workload: curved random sheets (the frustum benchmark's distribution: centres in a box around a
// perspective view, 0.2..1.0 across, about half outside the frustum), with bumps so that cones are
// neither degenerate nor always invalid, and displacement ranges of up to 10% of the patch size on
// either side. Counters: fraction frustum-culled, occluded.
//
// Run:
//   build-disp/bench/patchcull_bench --benchmark_filter='displaced_' --benchmark_repetitions=3
//       --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

struct DisplacedWorkload {
    PatchBatch batch;
    std::vector<DisplacementRange> ranges;
    Mat4 view, projection;
    DisplacedCullView cull_view;
    HiZPyramid hiz;
    std::vector<std::uint8_t> decision;
};

DisplacedWorkload& displaced_workload(std::size_t n) {
    static std::map<std::size_t, std::unique_ptr<DisplacedWorkload>> cache;
    auto& slot = cache[n];
    if (slot) return *slot;
    slot = std::make_unique<DisplacedWorkload>();
    DisplacedWorkload& w = *slot;
    std::mt19937 rng(static_cast<unsigned>(n) + 11);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    std::vector<BezierPatch> patches(n);
    w.ranges.resize(n);
    for (std::size_t p = 0; p < n; ++p) {
        const Vec3 c{30 * u(rng), 12 * u(rng), 30 * u(rng) - 10};
        const float size = 0.2f + 0.8f * unit(rng);
        const Vec3 a = Vec3{u(rng), u(rng), u(rng)} * size, b = Vec3{u(rng), u(rng), u(rng)} * size;
        const Vec3 normal = normalize(cross(a, b));
        const float bend = 0.3f * size * u(rng);
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const float s = i / 3.0f - 0.5f, t = j / 3.0f - 0.5f;
                const Vec3 pt = c + a * s + b * t + normal * (bend * (s * s + t * t) + 0.03f * size * u(rng));
                patches[p].cp[4 * j + i] = homogeneous(pt, 1.0f);
            }
        w.ranges[p] = {-0.1f * size * unit(rng), 0.1f * size * unit(rng)};
    }
    w.batch = make_batch(patches);
    w.view = look_at({0, 3, 15}, {0, 0, 0}, {0, 1, 0});
    w.projection = perspective(60.0f * 3.14159265f / 180, 16.0f / 9.0f, 0.1f, 200.0f);
    w.cull_view = make_displaced_cull_view(w.view, w.projection, ClipDepth::zero_to_one);
    // Occluders: a wall over the lower 40% of the screen at distance ~12, far background elsewhere.
    const int W = 1920, H = 1080;
    std::vector<float> depth(static_cast<std::size_t>(W) * H, 1.0f);
    const float n_plane = 0.1f, f_plane = 200.0f, d = 12.0f;
    const float wall = (f_plane / (f_plane - n_plane)) * (1 - n_plane / d);
    for (int y = 0; y < H * 2 / 5; ++y)
        for (int x = 0; x < W; ++x) depth[static_cast<std::size_t>(y) * W + x] = wall;
    w.hiz.build(depth.data(), W, H);
    w.decision.assign(n, 0);
    return w;
}

void count_outcomes(benchmark::State& state, const std::vector<std::uint8_t>& decision) {
    std::size_t frustum = 0, occluded = 0;
    for (std::uint8_t d : decision) {
        frustum += d == kHiZFrustumCulled;
        occluded += d == kHiZOccluded;
    }
    state.counters["frustum_culled"] = static_cast<double>(frustum) / static_cast<double>(decision.size());
    state.counters["occluded"] = static_cast<double>(occluded) / static_cast<double>(decision.size());
}

void bm_displaced(benchmark::State& state, DisplacedBoundKind bound, NormalConeKind cone, bool occlusion) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    DisplacedWorkload& w = displaced_workload(n);
    for (auto _ : state) {
        if (occlusion) {
            cull_displaced_occlusion(w.batch.view(), w.ranges.data(), bound, cone, w.cull_view, w.hiz,
                                     w.decision.data());
        } else {
            cull_displaced_frustum(w.batch.view(), w.ranges.data(), bound, cone, w.cull_view, w.decision.data());
        }
        benchmark::DoNotOptimize(w.decision.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
    if (occlusion) count_outcomes(state, w.decision);
}

void bm_nodisp(benchmark::State& state, bool hiz_kernel) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    DisplacedWorkload& w = displaced_workload(n);
    const Mat4 object_to_clip = w.projection * w.view;
    for (auto _ : state) {
        if (hiz_kernel) {
            cull_occlusion_scalar(w.batch.view(), object_to_clip, ClipDepth::zero_to_one, w.hiz, w.decision.data());
        } else {
            cull_displaced_occlusion(w.batch.view(), nullptr, DisplacedBoundKind::caf, NormalConeKind::full,
                                     w.cull_view, w.hiz, w.decision.data());
        }
        benchmark::DoNotOptimize(w.decision.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
    count_outcomes(state, w.decision);
}

int register_displaced() {
    for (bool occlusion : {false, true})
        for (DisplacedBoundKind bound : {DisplacedBoundKind::oobb, DisplacedBoundKind::caf})
            for (NormalConeKind cone : {NormalConeKind::full, NormalConeKind::acon, NormalConeKind::con}) {
                const std::string name = std::string(occlusion ? "displaced_occlusion/" : "displaced_frustum/") +
                                         displaced_bound_name(bound) + "_" + normal_cone_name(cone);
                benchmark::RegisterBenchmark(name.c_str(),
                                             [=](benchmark::State& s) { bm_displaced(s, bound, cone, occlusion); })
                    ->Arg(5168)
                    ->UseRealTime()
                    ->Unit(benchmark::kMicrosecond);
            }
    benchmark::RegisterBenchmark("displaced_occlusion/nodisp_caf", [](benchmark::State& s) { bm_nodisp(s, false); })
        ->Arg(5168)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark("displaced_occlusion/nodisp_hiz", [](benchmark::State& s) { bm_nodisp(s, true); })
        ->Arg(5168)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    return 0;
}

[[maybe_unused]] const int displaced_registered = register_displaced();

}  // namespace
