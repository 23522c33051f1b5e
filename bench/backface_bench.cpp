// Benchmarks of back-face culling (patchcull/objects/backface.h, backface_clusters.h; G. Zachmann's
// lecture "Advanced Visibility Computations": back-face culling, normal masks (Zhang & Hoff 1997),
// clustered back-face culling (Johannsen & Carter 1998)).
//
// - backface/dot_{scalar,simd}/T: the per-triangle test over T indexed triangles (a UV sphere,
//   eyes around it); items_per_second is triangles per second.
// - backface/mask_{scalar,simd}/T: the normal-mask lookup (N = 16, 1536 classes) over the same
//   triangles' precomputed classes; items_per_second is triangles per second; the `culled`
//   counters show that the mask keeps more. backface/make_mask/S: building the S x S sector masks
//   of one frame (S = 1: the whole frustum).
// - backface/cluster_test: cluster_backfacing on the leaves of the tessellated BigGuy;
//   items_per_second is cluster tests per second.
// - backface/hierarchy/<mesh>/<tC/r>: cull_cluster_hierarchy per frame (items: frames) with
//   counters: members culled by the clusters and by the per-primitive test (fractions of all
//   members, averaged over the frames), cluster tests per frame, and per-primitive tests per frame
//   (= members). Meshes: sphere (UV sphere, 131k triangles), box (tessellated box, 98k
//   triangles, flat faces like buildings), bigguy_tess (BigGuy's ACC patches tessellated 8 x 8,
//   186k triangles), and the patch meshes bigguy_acc_s<levels> (BigGuy's ACC patches after 0, 1
//   or 2 splits: 1450, 5800, 23200 patches), whose per-primitive test is ptp-pcnt (Loop, Niessner &
//   Eisenacher).
// - backface/ptp_frame/bigguy_acc_s<levels>: one frame of the per-patch ptp-pcnt kernel (SIMD) on
//   those patches, for the time the cluster tests stand against (items: frames).
//
// Run (numbers in docs/PERFORMANCE.md):
//   build-bf/bench/patchcull_bench --benchmark_filter='^backface/'
//       --benchmark_repetitions=3 --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/frustum.h"  // simd_target_name
#include "patchcull/import/model_loader.h"
#include "patchcull/objects/backface.h"
#include "patchcull/objects/backface_clusters.h"

using namespace patchcull;

namespace {

struct TriMesh {
    std::vector<Vec3> vertices;
    std::vector<std::uint32_t> indices;
    std::size_t triangles() const { return indices.size() / 3; }
};

TriMesh uv_sphere(int stacks, int slices) {
    TriMesh m;
    const double pi = 3.14159265358979323846;
    for (int i = 0; i <= stacks; ++i)
        for (int j = 0; j <= slices; ++j) {
            const double th = pi * i / stacks, ph = 2 * pi * j / slices;
            m.vertices.push_back(
                {float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th))});
        }
    for (int i = 0; i < stacks; ++i)
        for (int j = 0; j < slices; ++j) {
            const std::uint32_t a = i * (slices + 1) + j, b = a + slices + 1, c = b + 1, d = a + 1;
            // (theta, phi) grid: outward for the order a, b, c (then a, c, d).
            m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
        }
    return m;
}

TriMesh tessellated_box(int k) {
    TriMesh m;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const int b = (axis + 1) % 3, c = (axis + 2) % 3;
            const std::uint32_t base = static_cast<std::uint32_t>(m.vertices.size());
            for (int j = 0; j <= k; ++j)
                for (int i = 0; i <= k; ++i) {
                    float p[3];
                    p[axis] = side ? 1.0f : -1.0f;
                    p[b] = -1 + 2.0f * i / k;
                    p[c] = -1 + 2.0f * j / k;
                    m.vertices.push_back({p[0], p[1], p[2]});
                }
            for (int j = 0; j < k; ++j)
                for (int i = 0; i < k; ++i) {
                    const std::uint32_t a = base + j * (k + 1) + i, bb = a + 1, cc = a + k + 2, d = a + k + 1;
                    if (side)
                        m.indices.insert(m.indices.end(), {a, bb, cc, a, cc, d});
                    else
                        m.indices.insert(m.indices.end(), {a, cc, bb, a, d, cc});
                }
        }
    return m;
}

const LoadedModel& bigguy(int splits) {
    static std::map<int, std::unique_ptr<LoadedModel>> cache;
    auto& slot = cache[splits];
    if (!slot) slot = std::make_unique<LoadedModel>(load_model(shipped_model_path("bigguy.obj"), Scheme::acc, splits));
    return *slot;
}

// BigGuy's patches tessellated g x g (per-patch grids; patches share no vertices).
TriMesh bigguy_tessellated(int g) {
    TriMesh m;
    for (const BezierPatch& p : bigguy(0).rest.patches) {
        const std::uint32_t base = static_cast<std::uint32_t>(m.vertices.size());
        for (int j = 0; j <= g; ++j)
            for (int i = 0; i <= g; ++i) m.vertices.push_back(evaluate_position(p, float(i) / g, float(j) / g));
        for (int j = 0; j < g; ++j)
            for (int i = 0; i < g; ++i) {
                const std::uint32_t a = base + j * (g + 1) + i, b = a + 1, c = a + g + 2, d = a + g + 1;
                m.indices.insert(m.indices.end(), {a, b, c, a, c, d});  // du x dv outward
            }
    }
    return m;
}

struct Scene {
    TriMesh mesh;
    Vec3 centre{};
    float radius = 1;
    std::vector<Vec3> eyes;
    std::vector<Mat4> world_to_clip;
    std::vector<std::uint16_t> classes;
};

Scene& scene(const std::string& name) {
    static std::map<std::string, std::unique_ptr<Scene>> cache;
    auto& slot = cache[name];
    if (slot) return *slot;
    slot = std::make_unique<Scene>();
    Scene& s = *slot;
    if (name == "sphere")
        s.mesh = uv_sphere(256, 256);
    else if (name == "box")
        s.mesh = tessellated_box(90);
    else
        s.mesh = bigguy_tessellated(8);
    const Bounds b = compute_bounds(s.mesh.vertices);
    s.centre = b.center();
    s.radius = b.radius();
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int k = 0; k < 64; ++k) {
        Vec3 d{u(rng), u(rng), u(rng)};
        const Vec3 eye = s.centre + normalize(d) * (s.radius * (2.0f + 2.0f * (k % 2)));
        s.eyes.push_back(eye);
        s.world_to_clip.push_back(perspective(0.9f, 1.0f, 0.05f * s.radius, 20 * s.radius) *
                                  look_at(eye, s.centre, {0, 1, 0}));
    }
    const NormalMaskGrid grid(16);
    s.classes.resize(s.mesh.triangles());
    grid.classify_triangles(s.mesh.vertices.data(), s.mesh.indices.data(), s.mesh.triangles(), s.classes.data());
    return s;
}

void BM_Dot(benchmark::State& state, bool simd) {
    Scene& s = scene("sphere");
    std::vector<std::uint8_t> culled(s.mesh.triangles());
    std::size_t frame = 0, total = 0;
    for (auto _ : state) {
        const Vec3 eye = s.eyes[frame++ % s.eyes.size()];
        (simd ? cull_backfacing_triangles_simd : cull_backfacing_triangles_scalar)(
            s.mesh.vertices.data(), s.mesh.indices.data(), s.mesh.triangles(), eye, culled.data());
        benchmark::DoNotOptimize(culled.data());
        for (std::uint8_t c : culled) total += c;
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(s.mesh.triangles()));
    state.counters["culled"] = double(total) / double(state.iterations() * s.mesh.triangles());
    state.SetLabel(simd ? simd_target_name() : "scalar");
}

void BM_Mask(benchmark::State& state, bool simd) {
    Scene& s = scene("sphere");
    const NormalMaskGrid grid(16);
    std::vector<BackMask> masks(s.eyes.size());
    for (std::size_t k = 0; k < masks.size(); ++k)
        make_back_mask(grid, s.world_to_clip[k], ClipDepth::zero_to_one, 0, 0, 1, masks[k]);
    std::vector<std::uint8_t> culled(s.mesh.triangles());
    std::size_t frame = 0, total = 0;
    for (auto _ : state) {
        const BackMask& m = masks[frame++ % masks.size()];
        (simd ? cull_by_normal_mask_simd : cull_by_normal_mask_scalar)(s.classes.data(), s.classes.size(), m,
                                                                       culled.data());
        benchmark::DoNotOptimize(culled.data());
        for (std::uint8_t c : culled) total += c;
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(s.mesh.triangles()));
    state.counters["culled"] = double(total) / double(state.iterations() * s.mesh.triangles());
    state.SetLabel(simd ? simd_target_name() : "scalar");
}

void BM_MakeMask(benchmark::State& state) {
    Scene& s = scene("sphere");
    const int S = static_cast<int>(state.range(0));
    const NormalMaskGrid grid(16);
    BackMask m;
    std::size_t frame = 0;
    for (auto _ : state) {
        const Mat4& v = s.world_to_clip[frame++ % s.world_to_clip.size()];
        for (int y = 0; y < S; ++y)
            for (int x = 0; x < S; ++x) {
                make_back_mask(grid, v, ClipDepth::zero_to_one, x, y, S, m);
                benchmark::DoNotOptimize(m.bits.data());
            }
    }
    state.SetItemsProcessed(state.iterations());
}

struct HierarchyCase {
    ClusterHierarchy h;
    std::size_t members = 0;
    std::vector<Vec3> eyes;
    std::vector<std::vector<std::uint8_t>> per_primitive;  // per eye
};

HierarchyCase& hierarchy_case(const std::string& mesh, double tcr) {
    static std::map<std::pair<std::string, double>, std::unique_ptr<HierarchyCase>> cache;
    auto& slot = cache[{mesh, tcr}];
    if (slot) return *slot;
    slot = std::make_unique<HierarchyCase>();
    HierarchyCase& c = *slot;
    if (mesh.rfind("bigguy_acc_s", 0) == 0) {
        const LoadedModel& model = bigguy(mesh.back() - '0');
        const auto& patches = model.rest.patches;
        c.h = build_patch_clusters(patches.data(), patches.size(), tcr, 16);
        c.members = patches.size();
        const Bounds b = patch_bounds(model.rest);
        std::mt19937 rng(8);
        std::uniform_real_distribution<float> u(-1, 1);
        const PatchBatch batch = make_batch(patches);
        for (int k = 0; k < 32; ++k) {
            const Vec3 eye =
                b.center() + normalize(Vec3{u(rng), u(rng), u(rng)}) * (b.radius() * (2.0f + 2.0f * (k % 2)));
            const Mat4 proj = perspective(0.9f, 1.0f, 0.05f * b.radius(), 20 * b.radius());
            std::vector<std::uint8_t> out(patches.size());
            cull_ptp_simd(batch.view(), proj * look_at(eye, b.center(), {0, 1, 0}), clip_space_eye_alpha(proj),
                          PtpRule::pcnt, out.data());
            c.eyes.push_back(eye);
            c.per_primitive.push_back(std::move(out));
        }
        return c;
    }
    Scene& s = scene(mesh);
    c.h = build_triangle_clusters(s.mesh.vertices, s.mesh.indices, tcr, 64);
    c.members = s.mesh.triangles();
    for (std::size_t k = 0; k < 32; ++k) {
        std::vector<std::uint8_t> out(s.mesh.triangles());
        cull_backfacing_triangles_simd(s.mesh.vertices.data(), s.mesh.indices.data(), s.mesh.triangles(), s.eyes[k],
                                       out.data());
        c.eyes.push_back(s.eyes[k]);
        c.per_primitive.push_back(std::move(out));
    }
    return c;
}

void BM_Hierarchy(benchmark::State& state, std::string mesh, double tcr) {
    HierarchyCase& c = hierarchy_case(mesh, tcr);
    std::vector<std::uint8_t> leaf(cluster_leaf_count(c.h));
    std::size_t frame = 0;
    std::uint64_t tests = 0;
    for (auto _ : state) {
        std::uint32_t t = 0;
        cull_cluster_hierarchy(c.h, c.eyes[frame++ % c.eyes.size()], leaf.data(), t);
        tests += t;
        benchmark::DoNotOptimize(leaf.data());
    }
    // Cull fractions over the case's eyes (outside the timed loop).
    double by_cluster = 0, by_primitive = 0;
    for (std::size_t k = 0; k < c.eyes.size(); ++k) {
        std::uint32_t t = 0;
        cull_cluster_hierarchy(c.h, c.eyes[k], leaf.data(), t);
        for (std::size_t l = 0; l < leaf.size(); ++l)
            if (leaf[l]) by_cluster += cluster_leaf(c.h, l).count;
        for (std::uint8_t p : c.per_primitive[k]) by_primitive += p;
    }
    const double n = double(c.eyes.size() * c.members);
    state.SetItemsProcessed(state.iterations());
    state.counters["members"] = double(c.members);
    state.counters["leaves"] = double(cluster_leaf_count(c.h));
    state.counters["nodes"] = double(c.h.nodes.size());
    state.counters["cluster_tests_per_frame"] = double(tests) / double(state.iterations());
    state.counters["culled_by_clusters"] = by_cluster / n;
    state.counters["culled_per_primitive"] = by_primitive / n;
}

// The per-patch ptp-pcnt kernel (SIMD) on the same patches and eyes, per frame: what the
// clusters' tests replace (a culled cluster's patches need no per-patch test).
void BM_PtpFrame(benchmark::State& state, int splits) {
    const LoadedModel& model = bigguy(splits);
    const PatchBatch batch = make_batch(model.rest.patches);
    const Bounds b = patch_bounds(model.rest);
    const Mat4 proj = perspective(0.9f, 1.0f, 0.05f * b.radius(), 20 * b.radius());
    std::vector<Mat4> views;
    std::mt19937 rng(8);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int k = 0; k < 32; ++k) {
        const Vec3 eye = b.center() + normalize(Vec3{u(rng), u(rng), u(rng)}) * (b.radius() * (2.0f + 2.0f * (k % 2)));
        views.push_back(proj * look_at(eye, b.center(), {0, 1, 0}));
    }
    std::vector<std::uint8_t> out(batch.size());
    std::size_t frame = 0;
    for (auto _ : state) {
        cull_ptp_simd(batch.view(), views[frame++ % views.size()], clip_space_eye_alpha(proj), PtpRule::pcnt,
                      out.data());
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(state.iterations());
    state.counters["patches"] = double(batch.size());
    state.SetLabel(simd_target_name());
}

void BM_ClusterTest(benchmark::State& state) {
    HierarchyCase& c = hierarchy_case("bigguy_tess", 4.0);
    std::vector<BackfaceCluster> leaves;
    for (std::size_t l = 0; l < cluster_leaf_count(c.h); ++l) leaves.push_back(cluster_leaf(c.h, l));
    std::size_t frame = 0, culled = 0;
    for (auto _ : state) {
        const Vec3 eye = c.eyes[frame++ % c.eyes.size()];
        for (const BackfaceCluster& cl : leaves) culled += cluster_backfacing(cl, eye);
        benchmark::DoNotOptimize(culled);
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(leaves.size()));
    state.counters["culled"] = double(culled) / double(state.iterations() * leaves.size());
}

const bool registered = [] {
    benchmark::RegisterBenchmark("backface/dot_scalar", BM_Dot, false)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark("backface/dot_simd", BM_Dot, true)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark("backface/mask_scalar", BM_Mask, false)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark("backface/mask_simd", BM_Mask, true)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark("backface/make_mask", BM_MakeMask)
        ->Arg(1)
        ->Arg(2)
        ->Arg(4)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark("backface/cluster_test", BM_ClusterTest)->Unit(benchmark::kMicrosecond);
    for (const char* mesh : {"sphere", "box", "bigguy_tess"})
        for (double tcr : {1.0, 4.0, 16.0})
            benchmark::RegisterBenchmark(
                ("backface/hierarchy/" + std::string(mesh) + "/" + std::to_string(int(tcr))).c_str(), BM_Hierarchy,
                std::string(mesh), tcr)
                ->Unit(benchmark::kMicrosecond);
    for (const char* mesh : {"bigguy_acc_s0", "bigguy_acc_s1", "bigguy_acc_s2"})
        for (double tcr : {0.01, 0.1, 1.0})
            benchmark::RegisterBenchmark(
                ("backface/hierarchy/" + std::string(mesh) + "/" + std::to_string(tcr)).c_str(), BM_Hierarchy,
                std::string(mesh), tcr)
                ->Unit(benchmark::kMicrosecond);
    for (int splits : {0, 1, 2})
        benchmark::RegisterBenchmark(("backface/ptp_frame/bigguy_acc_s" + std::to_string(splits)).c_str(), BM_PtpFrame,
                                     splits)
            ->Unit(benchmark::kMicrosecond);
    return true;
}();

}  // namespace
