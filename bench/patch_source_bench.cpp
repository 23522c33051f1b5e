// Benchmarks of the frustum kernel over the caller's own control points (patchcull/core/
// patch_source.h) against the same kernel over a PatchBatch, at 65536 patches, one thread.
// items_per_second is patches per second.
//
// The surface is a 256 x 256 grid of patches over a wavy height field, seen from above at an
// angle (about half the patches outside the frustum), held three ways:
//   batch/plain, batch/blocked   PatchBatch and PatchBlocks of its Bezier patches (256 B a patch);
//   bezier_float3_indexed        its Bezier points once each (neighbours share edge points: 769^2
//                                points) as float3 in a 32-byte vertex (position, normal, uv), 16
//                                uint32 indices a patch: the gather reads 64 B of indices + 16 points;
//   bspline_float3_indexed       the same grid as B-spline control points (259^2 points, one a
//                                patch), converted to Bezier form during the gather;
//   check_only                   check_patch_source alone on the Bezier source (one pass over the
//                                indices), which every source entry runs first.
// Run:
//   build/bench/patchcull_bench --benchmark_filter='patch_source' --benchmark_repetitions=3
//       --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "cull_bench_loop.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/patch_source.h"

using namespace patchcull;

namespace {

constexpr int kGrid = 256;  // patches per side: 65536 patches
constexpr std::size_t kPatches = static_cast<std::size_t>(kGrid) * kGrid;
constexpr std::size_t kVertexBytes = 32;  // float3 position, float3 normal, float2 uv

struct Vertex {
    float position[3];
    float normal[3];
    float uv[2];
};
static_assert(sizeof(Vertex) == kVertexBytes);

float height(float x, float z) { return 0.6f * std::sin(0.37f * x) * std::cos(0.23f * z); }

struct Workload {
    PatchBatch batch;
    PatchBlocks blocks;
    std::vector<Vertex> bezier_points, bspline_points;
    std::vector<std::uint32_t> bezier_indices, bspline_indices;
    PatchSourceView bezier, bspline;
    CullView view;
    std::vector<std::uint8_t> culled;
};

Workload& workload() {
    static std::unique_ptr<Workload> slot;
    if (slot) return *slot;
    slot = std::make_unique<Workload>();
    Workload& w = *slot;
    const float spacing = 0.25f;  // between grid points; a patch is 3 (Bezier) or 1 (B-spline) spacing across
    // Bezier points: a (3 kGrid + 1)^2 grid; patch (a, b) uses rows 3b .. 3b + 3, columns 3a .. 3a + 3.
    const int nb = 3 * kGrid + 1;
    const auto vertex = [&](float x, float z) {
        Vertex v{};
        v.position[0] = x;
        v.position[1] = height(x, z);
        v.position[2] = z;
        v.normal[1] = 1;
        return v;
    };
    for (int r = 0; r < nb; ++r)
        for (int c = 0; c < nb; ++c) w.bezier_points.push_back(vertex(spacing * (c - nb / 2), spacing * (r - nb / 2)));
    std::vector<BezierPatch> patches(kPatches);
    for (int b = 0; b < kGrid; ++b)
        for (int a = 0; a < kGrid; ++a) {
            const std::size_t p = static_cast<std::size_t>(b) * kGrid + a;
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i) {
                    const std::uint32_t index = static_cast<std::uint32_t>((3 * b + j) * nb + 3 * a + i);
                    w.bezier_indices.push_back(index);
                    const float* q = w.bezier_points[index].position;
                    patches[p].cp[4 * j + i] = {q[0], q[1], q[2], 1};
                }
        }
    w.batch = make_batch(patches);
    w.blocks = PatchBlocks(w.batch.view());
    // B-spline points: a (kGrid + 3)^2 grid, 3 spacings apart (the same extent); patch (a, b) uses
    // rows b .. b + 3, columns a .. a + 3.
    const int ns = kGrid + 3;
    for (int r = 0; r < ns; ++r)
        for (int c = 0; c < ns; ++c)
            w.bspline_points.push_back(vertex(3 * spacing * (c - ns / 2), 3 * spacing * (r - ns / 2)));
    for (int b = 0; b < kGrid; ++b)
        for (int a = 0; a < kGrid; ++a)
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i)
                    w.bspline_indices.push_back(static_cast<std::uint32_t>((b + j) * ns + a + i));
    w.bezier = {{w.bezier_points.data(), kVertexBytes, 0, 3, w.bezier_points.size()},
                w.bezier_indices.data(),
                kPatches,
                PatchBasis::bezier};
    w.bspline = {{w.bspline_points.data(), kVertexBytes, 0, 3, w.bspline_points.size()},
                 w.bspline_indices.data(),
                 kPatches,
                 PatchBasis::bspline};
    // From above the grid's centre at an angle: about half of it in view.
    const Mat4 view = look_at({0, 40, 60}, {0, 0, 0}, {0, 1, 0});
    w.view = make_cull_view(view, perspective(0.8f, 16.0f / 9.0f, 0.1f, 500.0f, ClipDepth::zero_to_one),
                            ClipDepth::zero_to_one);
    w.culled.assign(kPatches, 0);
    return w;
}

enum class Input { kPlain, kBlocked, kBezierIndexed, kBsplineIndexed, kCheckOnly };

void bm_frustum(benchmark::State& state, Input input) {
    Workload& w = workload();
    std::uint8_t* culled = w.culled.data();
    bench::run_cull_benchmark(
        state, kPatches, culled, false, 0,
        [&](std::size_t, std::size_t) {
            switch (input) {
                case Input::kPlain:
                    cull_frustum(w.batch.view(), nullptr, w.view, culled);
                    break;
                case Input::kBlocked:
                    cull_frustum(w.blocks.view(), nullptr, w.view, culled);
                    break;
                case Input::kBezierIndexed:
                    cull_frustum(w.bezier, nullptr, w.view, culled);
                    break;
                case Input::kBsplineIndexed:
                    cull_frustum(w.bspline, nullptr, w.view, culled);
                    break;
                case Input::kCheckOnly:
                    check_patch_source(w.bezier, "bench");
                    break;
            }
        },
        [] { return simd_target_name(); });
}

int register_all() {
    const std::pair<const char*, Input> cases[] = {
        {"patch_source_frustum/batch_plain", Input::kPlain},
        {"patch_source_frustum/batch_blocked", Input::kBlocked},
        {"patch_source_frustum/bezier_float3_indexed", Input::kBezierIndexed},
        {"patch_source_frustum/bspline_float3_indexed", Input::kBsplineIndexed},
        {"patch_source_frustum/check_only", Input::kCheckOnly}};
    for (const auto& [name, input] : cases)
        benchmark::RegisterBenchmark(name, [input = input](benchmark::State& s) { bm_frustum(s, input); })
            ->UseRealTime()
            ->Unit(benchmark::kMicrosecond);
    return 0;
}

[[maybe_unused]] const int registered = register_all();

}  // namespace
