// Benchmarks of the patch-source entries (patchcull/core/patch_source.h: cull_frustum,
// cull_frustum_disp, cull_backpatch, cull_fused over the caller's own control points) against the
// same entries over a PatchBatch, at 65536 patches, one thread. items_per_second is patches per
// second.
//
// The surface is a 256 x 256 grid of patches over a wavy height field, seen from above at an
// angle (about half the patches outside the frustum), held four ways:
//   batch/plain, batch/blocked   PatchBatch and PatchBlocks of its Bezier patches (256 B a patch);
//   bezier_float3_indexed        its Bezier points once each (neighbours share edge points: 769^2
//                                points) as float3 in a 32-byte vertex (position, normal, uv), 16
//                                uint32 indices a patch: the gather reads 64 B of indices + 16 points;
//   bspline_float3_indexed       the same grid as B-spline control points (259^2 points, one a
//                                patch), converted to Bezier form during the gather;
//   gregory_float3_indexed       the Bezier patches as Gregory patches (OpenSubdiv's GREGORY_BASIS
//                                order, F+ = F- = the Bezier interior point, so the same surfaces):
//                                20 points of their own a patch (640 B) and 20 indices (80 B), the
//                                entries' scalar 20-point path;
//   check_only                   check_patch_source alone on the Bezier source (one pass over the
//                                indices), which every source entry runs first.
// Rows: patch_source_<entry>/<input>, entry in frustum (cull_frustum), frustum_disp
// (cull_frustum_disp, no displacement), tcone (cull_backpatch with BackpatchMethod::tcone) and fused
// (cull_fused, the default plan frustum -> tcone -> Hi-Z, on a 1920x1080 pyramid with one
// occluder in front of the middle ninth of the screen); batch_plain runs the PatchBatchView
// overload of the same entry.
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
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"
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
    std::vector<Vertex> bezier_points, bspline_points, gregory_points;
    std::vector<std::uint32_t> bezier_indices, bspline_indices, gregory_indices;
    PatchSourceView bezier, bspline, gregory;
    CullView view;
    HiZPyramid hiz;
    FusedCullSetup fused;
    std::vector<std::uint8_t> culled;
};

Workload& workload() {
    static std::unique_ptr<Workload> slot;
    if (slot) return *slot;
    slot = std::make_unique<Workload>();
    Workload& w = *slot;
    const float spacing = 0.25f;  // between grid points; a patch is 3 (Bezier) or 1 (B-spline) spacing across
    // Bezier points: a (3 kGrid + 1)^2 grid; patch (a, b) uses rows 3b .. 3b + 3, columns 3a .. 3a + 3,
    // its control point (i, j) at row 3b + i, column 3a + j: u runs along z and v along x, so the
    // normal (u x v direction) faces +y, the eye's side, and tcone culls only patches sloping away.
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
                    const std::uint32_t index = static_cast<std::uint32_t>((3 * b + i) * nb + 3 * a + j);
                    w.bezier_indices.push_back(index);
                    const float* q = w.bezier_points[index].position;
                    patches[p].cp[4 * j + i] = {q[0], q[1], q[2], 1};
                }
        }
    w.batch = make_batch(patches);
    w.blocks = PatchBlocks(w.batch.view());
    // Gregory points of each Bezier patch, corner c's P, E+, E-, F+, F- at 5c (patch_source.h):
    // the boundary points of the Bezier patch and F+ = F- = its interior point at that corner.
    static constexpr int kGregoryOfBezier[20][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {1, 1},   // corner (0, 0)
                                                    {3, 0}, {3, 1}, {2, 0}, {2, 1}, {2, 1},   // corner (1, 0)
                                                    {3, 3}, {2, 3}, {3, 2}, {2, 2}, {2, 2},   // corner (1, 1)
                                                    {0, 3}, {0, 2}, {1, 3}, {1, 2}, {1, 2}};  // corner (0, 1)
    for (std::size_t p = 0; p < kPatches; ++p)
        for (const auto& ij : kGregoryOfBezier) {
            w.gregory_indices.push_back(static_cast<std::uint32_t>(w.gregory_points.size()));
            w.gregory_points.push_back(w.bezier_points[w.bezier_indices[16 * p + 4 * ij[1] + ij[0]]]);
        }
    // B-spline points: a (kGrid + 3)^2 grid, 3 spacings apart (the same extent); patch (a, b) uses
    // rows b .. b + 3, columns a .. a + 3, point (i, j) at row b + i, column a + j as above.
    const int ns = kGrid + 3;
    for (int r = 0; r < ns; ++r)
        for (int c = 0; c < ns; ++c)
            w.bspline_points.push_back(vertex(3 * spacing * (c - ns / 2), 3 * spacing * (r - ns / 2)));
    for (int b = 0; b < kGrid; ++b)
        for (int a = 0; a < kGrid; ++a)
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i)
                    w.bspline_indices.push_back(static_cast<std::uint32_t>((b + i) * ns + a + j));
    w.bezier = {{w.bezier_points.data(), kVertexBytes, 0, 3, w.bezier_points.size()},
                w.bezier_indices.data(),
                kPatches,
                PatchBasis::bezier};
    w.bspline = {{w.bspline_points.data(), kVertexBytes, 0, 3, w.bspline_points.size()},
                 w.bspline_indices.data(),
                 kPatches,
                 PatchBasis::bspline};
    w.gregory = {{w.gregory_points.data(), kVertexBytes, 0, 3, w.gregory_points.size()},
                 w.gregory_indices.data(),
                 kPatches,
                 PatchBasis::gregory};
    // From above the grid's centre at an angle: about half of it in view.
    const Mat4 view = look_at({0, 40, 60}, {0, 0, 0}, {0, 1, 0});
    w.view = make_cull_view(view, perspective(0.8f, 16.0f / 9.0f, 0.1f, 500.0f, ClipDepth::zero_to_one),
                            ClipDepth::zero_to_one);
    // A 1920x1080 depth buffer at the far plane with one occluder over the middle ninth of the
    // screen at depth 0.99 (about 10 units from the eye): the fused kernel's Hi-Z stage.
    const int dw = 1920, dh = 1080;
    std::vector<float> depth(static_cast<std::size_t>(dw) * dh, 1.0f);
    for (int y = dh / 3; y < 2 * dh / 3; ++y)
        for (int x = dw / 3; x < 2 * dw / 3; ++x) depth[static_cast<std::size_t>(y) * dw + x] = 0.99f;
    w.hiz.build(depth.data(), dw, dh);
    w.fused = make_fused_setup(w.view, BackPatchCone::tcone, &w.hiz);
    w.culled.assign(kPatches, 0);
    return w;
}

enum class Input { kPlain, kBlocked, kBezierIndexed, kBsplineIndexed, kGregoryIndexed, kCheckOnly };
enum class Entry { kFrustum, kFrustumDisp, kTcone, kFused };

// Entry e over patches held as input (kBlocked and kCheckOnly: frustum only).
void bm_source(benchmark::State& state, Entry e, Input input) {
    Workload& w = workload();
    std::uint8_t* culled = w.culled.data();
    const auto run_batch = [&](const PatchBatchView& v) {
        switch (e) {
            case Entry::kFrustum:
                cull_frustum(v, nullptr, w.view, culled);
                break;
            case Entry::kFrustumDisp:
                cull_frustum_disp(v, nullptr, w.view, culled);
                break;
            case Entry::kTcone:
                cull_backpatch(BackpatchMethod::tcone, v, w.view, {}, culled);
                break;
            case Entry::kFused:
                cull_fused_simd(v, w.fused, FusedPlan{}, culled);
                break;
        }
    };
    const auto run_source = [&](const PatchSourceView& source) {
        switch (e) {
            case Entry::kFrustum:
                cull_frustum(source, nullptr, w.view, culled);
                break;
            case Entry::kFrustumDisp:
                cull_frustum_disp(source, nullptr, w.view, culled);
                break;
            case Entry::kTcone:
                cull_backpatch(BackpatchMethod::tcone, source, w.view, {}, culled);
                break;
            case Entry::kFused:
                cull_fused(source, w.fused, FusedPlan{}, culled);
                break;
        }
    };
    bench::run_cull_benchmark(
        state, kPatches, culled, false, 0,
        [&](std::size_t, std::size_t) {
            switch (input) {
                case Input::kPlain:
                    run_batch(w.batch.view());
                    break;
                case Input::kBlocked:
                    run_batch(w.blocks.view());
                    break;
                case Input::kBezierIndexed:
                    run_source(w.bezier);
                    break;
                case Input::kBsplineIndexed:
                    run_source(w.bspline);
                    break;
                case Input::kGregoryIndexed:
                    run_source(w.gregory);
                    break;
                case Input::kCheckOnly:
                    check_patch_source(w.bezier, "bench");
                    break;
            }
        },
        [] { return simd_target_name(); });
}

int register_all() {
    const std::pair<const char*, Input> inputs[] = {{"batch_plain", Input::kPlain},
                                                    {"batch_blocked", Input::kBlocked},
                                                    {"bezier_float3_indexed", Input::kBezierIndexed},
                                                    {"bspline_float3_indexed", Input::kBsplineIndexed},
                                                    {"gregory_float3_indexed", Input::kGregoryIndexed},
                                                    {"check_only", Input::kCheckOnly}};
    const std::pair<const char*, Entry> entries[] = {{"patch_source_frustum/", Entry::kFrustum},
                                                     {"patch_source_frustum_disp/", Entry::kFrustumDisp},
                                                     {"patch_source_tcone/", Entry::kTcone},
                                                     {"patch_source_fused/", Entry::kFused}};
    for (const auto& [prefix, entry] : entries)
        for (const auto& [input_name, input] : inputs) {
            if (entry != Entry::kFrustum && (input == Input::kBlocked || input == Input::kCheckOnly)) continue;
            const std::string name = std::string(prefix) + input_name;
            benchmark::RegisterBenchmark(name.c_str(),
                                         [e = entry, i = input](benchmark::State& s) { bm_source(s, e, i); })
                ->UseRealTime()
                ->Unit(benchmark::kMicrosecond);
        }
    return 0;
}

[[maybe_unused]] const int registered = register_all();

}  // namespace
