// Benchmarks of the object level (patchcull/objects/bounding_volumes.h, patchcull/objects/object_bvh.h; G.
// Zachmann, "Advanced Visibility Computations"): object tests per second for the sphere,
// AABB n/p-vertex, AABB 8-corner and OBB tests (single-volume calls, and the scalar and SIMD batch
// kernels), BVH build and refit time for 200-5000 objects, and BVH culling against the flat list
// with and without plane masking and coherence on a walk through a city-like grid of objects.
//
// Counters: outside / inside / intersecting fractions of the volume mix; plane_tests and
// nodes_visited per object per frame for the culls. items_per_second is volumes (objects) per
// second. One thread.
//
// Run (see docs/PERFORMANCE.md):
//   build-bench/bench/patchcull_bench --benchmark_filter='^object_' --benchmark_min_time=0.2
//       --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "patchcull/core/frustum.h"
#include "patchcull/objects/bounding_volumes.h"
#include "patchcull/objects/object_bvh.h"

using namespace patchcull;

namespace {

// ---- volume tests -----------------------------------------------------------------------------

struct VolumeWorkload {
    FrustumPlanes planes;
    std::vector<Sphere> spheres;
    std::vector<Bounds> boxes;
    std::vector<Obb> obbs;
    std::vector<Containment> out;
};

// n objects (16 points each, 1-16 units across, random orientation, so the OBBs are tighter than
// the AABBs) in a 320 x 20 x 320 block with the camera inside it looking down -z (fovy 60 degrees,
// 16:9, far 150): a mix of about 75% outside, 21% inside and 3% intersecting, like a city view.
const VolumeWorkload& volume_workload() {
    static VolumeWorkload w = [] {
        VolumeWorkload v;
        const std::size_t n = 4096;
        std::mt19937 rng(42);
        std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
        v.planes = make_frustum_planes(
            perspective(1.0472f, 16.0f / 9.0f, 0.1f, 150.0f) * look_at({0, 2, 0}, {0, 2, -10}, {0, 1, 0}),
            ClipDepth::zero_to_one);
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3 c{160 * u(rng), 10 * u(rng), 160 * u(rng) - 60};
            const float s = 0.5f + 7.5f * unit(rng) * unit(rng);
            std::vector<Vec3> pts;
            const Vec3 a = normalize({u(rng), u(rng), u(rng)}), b = normalize(cross(a, {u(rng), u(rng), u(rng)}));
            for (int k = 0; k < 16; ++k)
                pts.push_back(c + a * (s * u(rng)) + b * (0.5f * s * u(rng)) + cross(a, b) * (0.2f * s * u(rng)));
            v.spheres.push_back(sphere_of_points(pts.data(), pts.size()));
            v.boxes.push_back(aabb_of_points(pts.data(), pts.size()));
            v.obbs.push_back(obb_of_points(pts.data(), pts.size()));
        }
        v.out.resize(n);
        return v;
    }();
    return w;
}

void report_mix(benchmark::State& state, const std::vector<Containment>& out) {
    double o = 0, in = 0, x = 0;
    for (Containment c : out) (c == Containment::outside ? o : c == Containment::inside ? in : x) += 1;
    const double n = double(out.size());
    state.counters["outside"] = o / n;
    state.counters["inside"] = in / n;
    state.counters["intersecting"] = x / n;
}

enum class Vol { kSphere, kAabb, kAabbCorners, kObb };
enum class Impl { kSingle, kScalar, kSimd };

void object_tests(benchmark::State& state, Vol vol, Impl impl) {
    const VolumeWorkload& cw = volume_workload();
    VolumeWorkload& w = const_cast<VolumeWorkload&>(cw);
    const std::size_t n = w.boxes.size();
    std::uint32_t tests = 0;
    for (auto _ : state) {
        if (impl == Impl::kSingle) {
            for (std::size_t i = 0; i < n; ++i) {
                PlaneCullState st;
                switch (vol) {
                    case Vol::kSphere:
                        w.out[i] = classify_sphere(w.planes, w.spheres[i], st, tests);
                        break;
                    case Vol::kAabb:
                        w.out[i] = classify_aabb(w.planes, w.boxes[i], st, tests);
                        break;
                    case Vol::kAabbCorners:
                        w.out[i] = classify_aabb_corners(w.planes, w.boxes[i], tests);
                        break;
                    case Vol::kObb:
                        w.out[i] = classify_obb(w.planes, w.obbs[i], st, tests);
                        break;
                }
            }
        } else {
            const bool simd = impl == Impl::kSimd;
            switch (vol) {
                case Vol::kSphere:
                    (simd ? classify_spheres_simd : classify_spheres_scalar)(w.planes, w.spheres.data(), n,
                                                                             w.out.data());
                    break;
                case Vol::kAabb:
                    (simd ? classify_aabbs_simd : classify_aabbs_scalar)(w.planes, w.boxes.data(), n, w.out.data());
                    break;
                case Vol::kObb:
                    (simd ? classify_obbs_simd : classify_obbs_scalar)(w.planes, w.obbs.data(), n, w.out.data());
                    break;
                case Vol::kAabbCorners:
                    break;
            }
        }
        benchmark::DoNotOptimize(w.out.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
    if (impl == Impl::kSingle)
        state.counters["plane_tests_per_volume"] = double(tests) / (double(state.iterations()) * n);
    report_mix(state, w.out);
}

BENCHMARK_CAPTURE(object_tests, sphere_single, Vol::kSphere, Impl::kSingle);
BENCHMARK_CAPTURE(object_tests, sphere_scalar, Vol::kSphere, Impl::kScalar);
BENCHMARK_CAPTURE(object_tests, sphere_simd, Vol::kSphere, Impl::kSimd);
BENCHMARK_CAPTURE(object_tests, aabb_np_single, Vol::kAabb, Impl::kSingle);
BENCHMARK_CAPTURE(object_tests, aabb_np_scalar, Vol::kAabb, Impl::kScalar);
BENCHMARK_CAPTURE(object_tests, aabb_np_simd, Vol::kAabb, Impl::kSimd);
BENCHMARK_CAPTURE(object_tests, aabb_corners_single, Vol::kAabbCorners, Impl::kSingle);
BENCHMARK_CAPTURE(object_tests, obb_single, Vol::kObb, Impl::kSingle);
BENCHMARK_CAPTURE(object_tests, obb_scalar, Vol::kObb, Impl::kScalar);
BENCHMARK_CAPTURE(object_tests, obb_simd, Vol::kObb, Impl::kSimd);

// ---- BVH ---------------------------------------------------------------------------------------

// A city-like scene: n objects on a square grid of blocks (streets every 4th row and column left
// empty), 1-3 units wide, 1-6 high, each with a small velocity (characters walking); the camera
// walks down the middle street at eye height. frames: frusta of a walk of 64 steps.
struct CityScene {
    std::vector<Bounds> boxes;
    std::vector<Vec3> velocity;
    std::vector<FrustumPlanes> frames;
};

const CityScene& city(std::size_t n) {
    static std::map<std::size_t, std::unique_ptr<CityScene>> cache;
    auto& slot = cache[n];
    if (slot) return *slot;
    slot = std::make_unique<CityScene>();
    CityScene& s = *slot;
    std::mt19937 rng(static_cast<unsigned>(n));
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    const int side = static_cast<int>(std::ceil(std::sqrt(double(n) * 16 / 9)));
    const float spacing = 4;
    for (int i = 0; static_cast<std::size_t>(s.boxes.size()) < n; ++i) {
        const int gx = i % side, gz = i / side;
        if (gx % 4 == 0 || gz % 4 == 0) continue;  // streets
        const float x = (gx - side / 2) * spacing, z = -gz * spacing;
        const float w = 0.5f + unit(rng), h = 0.5f + 2.5f * unit(rng);
        s.boxes.push_back({{x - w, 0, z - w}, {x + w, 2 * h, z + w}});
        s.velocity.push_back(Vec3{u(rng), 0, u(rng)} * 0.05f);
    }
    const float street_x = ((side / 2) / 4 * 4 - side / 2) * spacing;
    for (int f = 0; f < 64; ++f) {
        const Vec3 eye{street_x, 1.7f, 2.0f - 0.5f * f};
        const float yaw = 0.3f * std::sin(0.1f * f);
        const Vec3 target = eye + Vec3{std::sin(yaw), 0, -std::cos(yaw)};
        s.frames.push_back(
            make_frustum_planes(perspective(1.0472f, 16.0f / 9.0f, 0.1f, 120.0f) * look_at(eye, target, {0, 1, 0}),
                                ClipDepth::zero_to_one));
    }
    return s;
}

void bm_bvh_build(benchmark::State& state) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    const CityScene& s = city(n);
    ObjectBvh bvh;
    for (auto _ : state) {
        bvh.build(s.boxes.data(), n);
        benchmark::DoNotOptimize(bvh.node_count());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
    state.counters["nodes"] = double(bvh.node_count());
    state.counters["depth"] = double(bvh.depth());
}
BENCHMARK(bm_bvh_build)->Name("object_bvh_build")->Arg(200)->Arg(1000)->Arg(5000)->Unit(benchmark::kMicrosecond);

void bm_bvh_refit(benchmark::State& state) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    const CityScene& s = city(n);
    ObjectBvh bvh;
    bvh.build(s.boxes.data(), n);
    std::vector<Bounds> moved = s.boxes;
    for (std::size_t i = 0; i < n; ++i) moved[i].min += s.velocity[i], moved[i].max += s.velocity[i];
    bool flip = false;
    for (auto _ : state) {
        bvh.refit(flip ? s.boxes.data() : moved.data());  // alternates between two poses
        flip = !flip;
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
}
BENCHMARK(bm_bvh_refit)->Name("object_bvh_refit")->Arg(200)->Arg(1000)->Arg(5000)->Unit(benchmark::kMicrosecond);

// One frame per iteration, cycling through the walk; the objects stay where they are (the
// comparison is the traversal, refit is measured above).
void object_cull(benchmark::State& state, bool use_bvh, bool masking, bool coherence) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    const CityScene& s = city(n);
    ObjectBvh bvh;
    bvh.build(s.boxes.data(), n);
    std::vector<PlaneCullState> states(n);
    std::vector<Containment> out(n);
    ObjectBvh::Stats stats;
    std::size_t frame = 0;
    std::int64_t frames = 0;
    for (auto _ : state) {
        const FrustumPlanes& planes = s.frames[frame];
        frame = (frame + 1) % s.frames.size();
        if (use_bvh) {
            bvh.cull(planes, {masking, coherence}, out.data(), stats);
        } else {
            cull_objects_flat(planes, s.boxes.data(), n, states.data(), coherence, out.data(), stats);
        }
        benchmark::DoNotOptimize(out.data());
        ++frames;
    }
    state.SetItemsProcessed(frames * static_cast<std::int64_t>(n));
    state.counters["plane_tests_per_object"] = double(stats.plane_tests) / (double(frames) * n);
    state.counters["nodes_per_frame"] = double(stats.nodes_visited) / double(frames);
    // The mix over the whole walk (every variant gives the same answers).
    std::vector<Containment> all;
    for (const FrustumPlanes& planes : s.frames) {
        ObjectBvh::Stats unused;
        cull_objects_flat(planes, s.boxes.data(), n, nullptr, false, out.data(), unused);
        all.insert(all.end(), out.begin(), out.end());
    }
    report_mix(state, all);
}

BENCHMARK_CAPTURE(object_cull, flat, false, false, false)->Arg(200)->Arg(2000)->Arg(5000);
BENCHMARK_CAPTURE(object_cull, flat_coherence, false, false, true)->Arg(200)->Arg(2000)->Arg(5000);
BENCHMARK_CAPTURE(object_cull, bvh, true, false, false)->Arg(200)->Arg(2000)->Arg(5000);
BENCHMARK_CAPTURE(object_cull, bvh_masking, true, true, false)->Arg(200)->Arg(2000)->Arg(5000);
BENCHMARK_CAPTURE(object_cull, bvh_coherence, true, false, true)->Arg(200)->Arg(2000)->Arg(5000);
BENCHMARK_CAPTURE(object_cull, bvh_masking_coherence, true, true, true)->Arg(200)->Arg(2000)->Arg(5000);

}  // namespace
