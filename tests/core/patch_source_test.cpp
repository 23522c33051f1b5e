// Kernels over the caller's own control points (patchcull/core/patch_source.h): float3 and float4
// points at odd strides and offsets, with and without index lists, decide exactly as the batch
// kernels on the same Bezier patches; B-spline spans (interior, boundary and corner patches under
// OpenSubdiv's boundary mask) convert to Bezier patches of the same surface and decide as the
// batch of those; Gregory patches are never culled where a dense sample of their surface is
// visible, and are culled when wholly outside; bad views are refused with a message. Every entry:
// frustum, frustum-disp, the back-patch methods, occlusion, the fused kernel (every plan, both
// cones), and their parallel twins (parallel_cull.h), against the batch kernels in every ClipDepth
// convention.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "core/test_patches.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/parallel_cull.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/patch_source.h"

namespace patchcull {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int W = 64, H = 48;

// ---- a scene: one view, a depth layer, patches around it ------------------------------------------

struct Scene {
    CullView view;
    HiZPyramid hiz;
    std::vector<float> depth;  // W x H window depths in view.depth's convention (forward or reversed)
    Mat4 to_world;             // view space -> object space
};

// A camera at a random place, a depth layer of random rectangles at view distances 3..9 over the
// far plane, in convention depth (window depth = NDC z, or (z + 1) / 2 for minus_one_to_one).
Scene make_scene(std::uint32_t seed, ClipDepth depth) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    Scene s;
    const Vec3 eye{3 * u(rng), 3 * u(rng), 3 * u(rng)};
    const Mat4 view = look_at(eye, eye + Vec3{u(rng), u(rng), u(rng) - 1.5f}, {0, 1, 0});
    const Mat4 projection = perspective(1.0f, float(W) / float(H), 0.1f, 100.0f, depth);
    s.view = make_cull_view(view, projection, depth);
    invert(view, s.to_world);
    const bool reversed = is_reversed(depth);
    s.depth.assign(static_cast<std::size_t>(W) * H, reversed ? 0.0f : 1.0f);
    for (int r = 0; r < 10; ++r) {
        const int x0 = static_cast<int>(unit(rng) * W), y0 = static_cast<int>(unit(rng) * H);
        const int w = 1 + static_cast<int>(unit(rng) * W * 0.6f), h = 1 + static_cast<int>(unit(rng) * H * 0.6f);
        const Vec4 c = projection * Vec4{0, 0, -(3 + 6 * unit(rng)), 1};
        const float ndc = c.z / c.w;
        const float z = depth == ClipDepth::minus_one_to_one ? 0.5f * ndc + 0.5f : ndc;
        for (int y = y0; y < std::min(H, y0 + h); ++y)
            for (int x = x0; x < std::min(W, x0 + w); ++x) {
                float& d = s.depth[static_cast<std::size_t>(y) * W + x];
                d = reversed ? std::max(d, z) : std::min(d, z);
            }
    }
    s.hiz.build(s.depth.data(), W, H, depth);
    return s;
}

// A random curved 4 x 4 grid of points (view space, placed in front of, beside or behind the
// camera, some facing away), taken to object space; weights random in 0.5..2 when rational.
std::array<Vec4, 16> random_grid(std::mt19937& rng, const Scene& s, bool rational) {
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    const float dist = 1 + 14 * unit(rng);
    const float spread = rng() % 3 == 0 ? 3.0f : 1.0f;
    const Vec3 centre{dist * 0.6f * u(rng) * spread, dist * 0.5f * u(rng) * spread, -dist};
    const float size = dist * (0.03f + 0.2f * unit(rng));
    const Vec3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
    std::array<Vec4, 16> g;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const float x = i / 3.0f - 0.5f, y = j / 3.0f - 0.5f;
            const Vec3 pv = centre + (a * x + b * y) * size + cross(a, b) * (0.3f * size * (x * x + y * y) * u(rng));
            const Vec4 w4 = s.to_world * Vec4{pv.x, pv.y, pv.z, 1};
            g[4 * j + i] = homogeneous(Vec3{w4.x, w4.y, w4.z}, rational ? 0.5f + 1.5f * unit(rng) : 1.0f);
        }
    return g;
}

// ---- a source: the points of some patches in an interleaved vertex buffer ---------------------------

struct Source {
    std::vector<unsigned char> bytes;
    std::vector<std::uint32_t> indices;
    std::vector<std::uint8_t> masks;
    PatchSourceView view;
};

struct Layout {
    int components;
    std::size_t stride, offset;
    bool indexed;
};

// patches[p] holds n points; layout decides how they are stored. Indexed sources store the
// distinct points once each (bit-identical points share an index), shuffled, among unused
// points; skip[p] bit k: slot k of patch p holds garbage (a NaN point, or index 0xFFFFFFFF).
template <std::size_t N>
Source make_source(const std::vector<std::array<Vec4, N>>& patches, const Layout& layout, PatchBasis basis,
                   const std::vector<std::uint32_t>& skip = {}) {
    Source s;
    std::vector<Vec4> pool;
    std::vector<std::uint32_t> slot_index;
    const auto garbage = [&](std::size_t p, std::size_t k) { return !skip.empty() && ((skip[p] >> k) & 1u); };
    if (layout.indexed) {
        std::map<std::array<std::uint32_t, 4>, std::uint32_t> seen;
        for (std::size_t p = 0; p < patches.size(); ++p)
            for (std::size_t k = 0; k < N; ++k) {
                if (garbage(p, k)) {
                    slot_index.push_back(0xFFFFFFFFu);
                    continue;
                }
                std::array<std::uint32_t, 4> key;
                std::memcpy(key.data(), &patches[p][k], sizeof key);
                auto [it, added] = seen.emplace(key, static_cast<std::uint32_t>(pool.size()));
                if (added) pool.push_back(patches[p][k]);
                slot_index.push_back(it->second);
            }
        // Shuffle the pool (and remap), with some unused points among them.
        for (int e = 0; e < 37; ++e) pool.push_back({1e30f, -1e30f, kNaN, 1});
        std::vector<std::uint32_t> order(pool.size());
        std::iota(order.begin(), order.end(), 0u);
        std::mt19937 rng(static_cast<unsigned>(pool.size()));
        std::shuffle(order.begin(), order.end(), rng);
        std::vector<std::uint32_t> where(pool.size());
        std::vector<Vec4> shuffled(pool.size());
        for (std::size_t i = 0; i < order.size(); ++i) {
            shuffled[i] = pool[order[i]];
            where[order[i]] = static_cast<std::uint32_t>(i);
        }
        pool.swap(shuffled);
        for (std::uint32_t& i : slot_index)
            if (i != 0xFFFFFFFFu) i = where[i];
        s.indices = slot_index;
    } else {
        for (std::size_t p = 0; p < patches.size(); ++p)
            for (std::size_t k = 0; k < N; ++k)
                pool.push_back(garbage(p, k) ? Vec4{kNaN, kNaN, kNaN, kNaN} : patches[p][k]);
    }
    s.bytes.assign(pool.size() * layout.stride + 64, 0xCD);
    for (std::size_t i = 0; i < pool.size(); ++i) {
        const Vec4 q = pool[i];
        const float xyzw[4] = {q.x, q.y, q.z, q.w};
        std::memcpy(s.bytes.data() + i * layout.stride + layout.offset, xyzw,
                    static_cast<std::size_t>(layout.components) * sizeof(float));
    }
    s.view.points = {s.bytes.data(), layout.stride, layout.offset, layout.components, pool.size()};
    s.view.indices = layout.indexed ? s.indices.data() : nullptr;
    s.view.count = patches.size();
    s.view.basis = basis;
    return s;
}

std::vector<std::array<Vec4, 16>> grids_of(const std::vector<BezierPatch>& patches) {
    std::vector<std::array<Vec4, 16>> out(patches.size());
    for (std::size_t p = 0; p < patches.size(); ++p) std::copy(patches[p].cp, patches[p].cp + 16, out[p].begin());
    return out;
}

const Layout kLayouts[] = {
    {3, 29, 3, false},                     // float3 at an odd stride and offset, consecutive points
    {3, 12, 0, true},                      // packed float3, indexed
    {3, 29, 3, true},  {4, 23, 5, false},  // float4 at an odd stride and offset
    {4, 16, 0, true},  {4, 37, 17, true},
};

std::string layout_name(const Layout& l) {
    return "float" + std::to_string(l.components) + " stride " + std::to_string(l.stride) + " offset " +
           std::to_string(l.offset) + (l.indexed ? " indexed" : " consecutive");
}

// Every entry point on source against the batch kernels on batch; counts of culls per test added
// to culled (the comparisons must have teeth).
void expect_same_decisions(const PatchSourceView& source, const PatchBatchView& batch, const Scene& s,
                           std::map<std::string, std::size_t>& culled) {
    const std::size_t n = batch.count;
    ASSERT_EQ(source.count, n);
    std::vector<float> disp(n);
    for (std::size_t i = 0; i < n; ++i) disp[i] = 0.05f * static_cast<float>(i % 7);
    std::vector<std::uint8_t> want(n + 16, 0xAB), got(n + 16, 0xAB);
    const auto compare = [&](const std::string& what) {
        for (std::size_t i = n; i < got.size(); ++i) ASSERT_EQ(got[i], 0xAB) << what << ": wrote past count";
        for (std::size_t i = 0; i < n; ++i) {
            ASSERT_EQ(got[i], want[i]) << what << ": patch " << i;
            culled[what] += want[i] != 0;
        }
    };
    cull_frustum(batch, nullptr, s.view, want.data());
    cull_frustum(source, nullptr, s.view, got.data());
    compare("frustum");
    cull_frustum(batch, disp.data(), s.view, want.data());
    cull_frustum(source, disp.data(), s.view, got.data());
    compare("frustum+disp");
    for (BackpatchMethod id : backpatch_method_ids())
        for (PtpRule rule : {PtpRule::ncnt, PtpRule::pcnt}) {
            cull_backpatch(id, batch, s.view, BackpatchOptions{rule}, want.data());
            cull_backpatch(id, source, s.view, BackpatchOptions{rule}, got.data());
            compare(std::string(backpatch_method_name(id)) + (rule == PtpRule::ncnt ? "" : "-pcnt"));
        }
    cull_occlusion(batch, s.view, s.hiz, want.data());
    cull_occlusion(source, s.view, s.hiz, got.data());
    compare("occlusion");
    std::size_t occluded = 0;
    for (std::size_t i = 0; i < n; ++i) occluded += want[i] == kHiZOccluded;
    culled["occluded"] += occluded;
    cull_occlusion_parallel(source, s.view, s.hiz, got.data());
    compare("occlusion parallel");
    cull_frustum_parallel(source, disp.data(), s.view, got.data());
    cull_frustum(batch, disp.data(), s.view, want.data());
    compare("frustum+disp parallel");
    cull_backpatch(BackpatchMethod::ncone, batch, s.view, {}, want.data());
    cull_backpatch_parallel(BackpatchMethod::ncone, source, s.view, {}, got.data());
    compare("ncone parallel");

    // frustum-disp: Sathe's box, without and with displacement.
    for (const float* d : {static_cast<const float*>(nullptr), static_cast<const float*>(disp.data())}) {
        const std::string what = d ? "frustum-disp+disp" : "frustum-disp";
        cull_frustum_disp(batch, d, s.view, want.data());
        cull_frustum_disp(source, d, s.view, got.data());
        compare(what);
        cull_frustum_disp_parallel(source, d, s.view, got.data());
        compare(what + " parallel");
    }

    // The fused kernel: every valid plan of one, two or three stages, both cones; the statistics
    // equal cull_fused_simd's on the batch too.
    for (BackPatchCone cone : {BackPatchCone::tcone, BackPatchCone::ncone}) {
        const FusedCullSetup setup = make_fused_setup(s.view, cone, &s.hiz);
        for (unsigned stages = 1; stages < 8; ++stages) {
            FusedPlan plans[6];
            const int count = fused_plans_of(stages, plans);
            for (int k = 0; k < count; ++k) {
                const std::string what =
                    "fused " + fused_plan_name(plans[k]) + (cone == BackPatchCone::tcone ? " tcone" : " ncone");
                FusedCullStats want_stats, got_stats;
                cull_fused_simd(batch, setup, plans[k], want.data(), &want_stats);
                cull_fused(source, setup, plans[k], got.data(), &got_stats);
                compare(what);
                EXPECT_EQ(got_stats.groups, want_stats.groups) << what;
                for (int q = 0; q < kFusedStages; ++q) {
                    EXPECT_EQ(got_stats.groups_entered[q], want_stats.groups_entered[q]) << what;
                    EXPECT_EQ(got_stats.patches_culled[q], want_stats.patches_culled[q]) << what;
                }
                if (stages == 7) {
                    cull_fused_parallel(source, setup, plans[k], got.data());
                    compare(what + " parallel");
                }
            }
        }
    }
}

void expect_teeth(const std::map<std::string, std::size_t>& culled, std::size_t total) {
    for (const auto& [what, c] : culled) {
        EXPECT_GT(c, 0u) << what << " culled nothing: the comparison has no teeth";
        if (what != "occluded") {
            EXPECT_LT(c, total) << what << " culled everything";
        }
    }
}

TEST(PatchSource, BezierPointsAnyLayoutDecideAsTheBatch) {
    for (ClipDepth depth :
         {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed, ClipDepth::reversed_infinite}) {
        const Scene s = make_scene(7 + static_cast<std::uint32_t>(depth), depth);
        std::mt19937 rng(11);
        for (const Layout& layout : kLayouts) {
            SCOPED_TRACE(layout_name(layout));
            std::vector<BezierPatch> patches;
            for (int i = 0; i < 997; ++i) {  // not a multiple of 16: a partial last block
                BezierPatch p;
                const std::array<Vec4, 16> g = random_grid(rng, s, layout.components == 4 && i % 5 == 0);
                std::copy(g.begin(), g.end(), p.cp);
                patches.push_back(p);
            }
            // Split teapot patches share their edge points exactly: indexed sources share them.
            for (const BezierPatch& t : test_patches::split_teapot(1)) {
                BezierPatch p;
                for (int k = 0; k < 16; ++k) {
                    const Vec3 c = cartesian(t.cp[k]);
                    const Vec4 w4 = s.to_world * Vec4{c.x, c.y, c.z - 6, 1};
                    p.cp[k] = {w4.x, w4.y, w4.z, 1};
                }
                patches.push_back(p);
            }
            const Source src = make_source(grids_of(patches), layout, PatchBasis::bezier);
            if (layout.indexed) {
                EXPECT_LT(src.view.points.point_count, 16 * patches.size());
            }
            const PatchBatch batch = make_batch(patches);
            for (std::size_t p : {std::size_t{0}, std::size_t{500}, patches.size() - 1}) {
                const BezierPatch q = source_bezier_patch(src.view, p);
                for (int k = 0; k < 16; ++k) EXPECT_TRUE(test_patches::bit_identical(q.cp[k], patches[p].cp[k]));
            }
            std::map<std::string, std::size_t> culled;
            expect_same_decisions(src.view, batch.view(), s, culled);
            expect_teeth(culled, patches.size());
        }
    }
}

TEST(PatchSource, GatherWritesOneBlockWithZeroPadding) {
    const Scene s = make_scene(3, ClipDepth::zero_to_one);
    std::mt19937 rng(5);
    std::vector<std::array<Vec4, 16>> grids;
    grids.reserve(21);
    for (int i = 0; i < 21; ++i) grids.push_back(random_grid(rng, s, false));
    const Source src = make_source(grids, {3, 20, 4, true}, PatchBasis::bezier);
    std::vector<float> block(kBlockFloats, 7.0f);
    gather_bezier(src.view, 16, 5, block.data());
    const PatchBatchView v{block.data(), 5, kBlockPatches, kBlockFloats};
    for (std::size_t j = 0; j < kBlockPatches; ++j)
        for (int k = 0; k < 16; ++k)
            for (int c = 0; c < 4; ++c) {
                const float got = block[static_cast<std::size_t>(4 * k + c) * kBlockPatches + j];
                if (j >= 5) {
                    EXPECT_EQ(got, 0.0f);
                    continue;
                }
                const Vec4 want = grids[16 + j][k];
                EXPECT_EQ(got, (&want.x)[c]);
                EXPECT_EQ(v.at(j, k, c), got);
            }
}

TEST(PatchSource, NonFinitePointsAreNeverCulled) {
    // A patch far left of the view (culled by frustum), copies with one coordinate NaN or infinite.
    const Scene s = make_scene(21, ClipDepth::zero_to_one);
    BezierPatch base;
    for (int k = 0; k < 16; ++k) {
        const int col = k % 4, row = k / 4;
        const Vec4 w4 = s.to_world * Vec4{-50.0f + static_cast<float>(col), static_cast<float>(row), -5, 1};
        base.cp[k] = {w4.x, w4.y, w4.z, 1};
    }
    std::vector<BezierPatch> patches = test_patches::poisoned_copies(base);
    std::vector<std::array<Vec4, 16>> grids = grids_of(patches);
    for (int components : {3, 4}) {
        const Source src = make_source(grids, {components, 28, 8, true}, PatchBasis::bezier);
        std::vector<std::uint8_t> culled(grids.size(), 7);
        cull_frustum(src.view, nullptr, s.view, culled.data());
        EXPECT_EQ(culled[0], 1) << "the finite patch is outside";
        for (std::size_t i = 1; i < grids.size(); ++i) {
            const bool w_only = (i - 1) / 3 % 4 == 3;
            if (components == 3 && w_only) continue;  // float3 has no w to poison
            EXPECT_EQ(culled[i], 0) << "copy " << i;
        }
        cull_occlusion(src.view, s.view, s.hiz, culled.data());
        for (std::size_t i = 1; i < grids.size(); ++i)
            if (!(components == 3 && (i - 1) / 3 % 4 == 3)) {
                EXPECT_EQ(culled[i], kHiZVisible) << "copy " << i;
            }
        cull_frustum_disp(src.view, nullptr, s.view, culled.data());
        EXPECT_EQ(culled[0], 1) << "the finite patch is outside";
        for (std::size_t i = 1; i < grids.size(); ++i)
            if (!(components == 3 && (i - 1) / 3 % 4 == 3)) {
                EXPECT_EQ(culled[i], 0) << "frustum-disp, copy " << i;
            }
        cull_fused(src.view, make_fused_setup(s.view, BackPatchCone::ncone, &s.hiz), FusedPlan{}, culled.data());
        EXPECT_EQ(culled[0], kFusedFrustumCulled);
        for (std::size_t i = 1; i < grids.size(); ++i)
            if (!(components == 3 && (i - 1) / 3 % 4 == 3)) {
                EXPECT_EQ(culled[i], kFusedVisible) << "fused, copy " << i;
            }
    }
}

// ---- B-spline -----------------------------------------------------------------------------------

// Uniform cubic B-spline basis at t (double).
void bspline_basis(double t, double w[4]) {
    const double t2 = t * t, t3 = t2 * t;
    w[0] = (1 - 3 * t + 3 * t2 - t3) / 6;
    w[1] = (4 - 6 * t2 + 3 * t3) / 6;
    w[2] = (1 + 3 * t + 3 * t2 - 3 * t3) / 6;
    w[3] = t3 / 6;
}

// The B-spline patch at (s, t) with OpenSubdiv's boundary rule, written as Far adjusts its
// weights: a phantom end point's weight w moves to its neighbours (+2w next to it, -w beyond) and
// the phantom's slot gets weight 0 (never read here). Homogeneous result in double.
std::array<double, 4> eval_bspline(const std::array<Vec4, 16>& g, unsigned mask, double s, double t) {
    double ws[4], wt[4];
    bspline_basis(s, ws);
    bspline_basis(t, wt);
    const auto fold = [](double w[4], bool lo, bool hi) {
        if (lo) {
            w[1] += 2 * w[0];
            w[2] -= w[0];
            w[0] = 0;
        }
        if (hi) {
            w[2] += 2 * w[3];
            w[1] -= w[3];
            w[3] = 0;
        }
    };
    fold(wt, mask & 1, mask & 4);  // rows: v = 0 (bit 0), v = 1 (bit 2)
    fold(ws, mask & 8, mask & 2);  // columns: u = 0 (bit 3), u = 1 (bit 1)
    std::array<double, 4> out{0, 0, 0, 0};
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) {
            const double w = ws[col] * wt[row];
            if (w == 0) continue;  // a phantom slot
            const Vec4 q = g[4 * row + col];
            out[0] += w * q.x;
            out[1] += w * q.y;
            out[2] += w * q.z;
            out[3] += w * q.w;
        }
    return out;
}

// Slots beyond the boundary edges of mask (bit k: slot k is a phantom).
std::uint32_t phantom_slots(unsigned mask) {
    std::uint32_t out = 0;
    for (int k = 0; k < 16; ++k) {
        const int row = k / 4, col = k % 4;
        if (((mask & 1) && row == 0) || ((mask & 2) && col == 3) || ((mask & 4) && row == 3) ||
            ((mask & 8) && col == 0))
            out |= 1u << k;
    }
    return out;
}

TEST(PatchSource, BsplineConvertsToTheSameSurfaceAndDecidesAsItsBezierBatch) {
    for (ClipDepth depth :
         {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed, ClipDepth::reversed_infinite}) {
        const Scene s = make_scene(31 + static_cast<std::uint32_t>(depth), depth);
        std::mt19937 rng(41);
        for (const Layout& layout : kLayouts) {
            SCOPED_TRACE(layout_name(layout));
            std::vector<std::array<Vec4, 16>> grids;
            std::vector<std::uint8_t> masks;
            std::vector<std::uint32_t> skip;
            for (int i = 0; i < 803; ++i) {
                grids.push_back(random_grid(rng, s, layout.components == 4 && i % 3 == 0));
                const unsigned mask = i % 2 ? static_cast<unsigned>(i / 2 % 16) : 0u;  // every boundary and corner case
                masks.push_back(static_cast<std::uint8_t>(mask));
                skip.push_back(phantom_slots(mask));  // phantoms hold garbage: never read
            }
            Source src = make_source(grids, layout, PatchBasis::bspline, skip);
            src.masks = masks;
            src.view.boundary_mask = src.masks.data();
            // Same surface: the converted Bezier patch against the B-spline with phantom rule.
            std::vector<BezierPatch> converted(grids.size());
            for (std::size_t p = 0; p < grids.size(); ++p) {
                converted[p] = source_bezier_patch(src.view, p);
                double scale = 0;
                for (const Vec4& q : grids[p])
                    scale = std::max({scale, std::fabs(double(q.x) / q.w), std::fabs(double(q.y) / q.w),
                                      std::fabs(double(q.z) / q.w)});
                for (int a = 0; a <= 6; ++a)
                    for (int b = 0; b <= 6; ++b) {
                        const double u = a / 6.0, v = b / 6.0;
                        const std::array<double, 4> want = eval_bspline(grids[p], masks[p], u, v);
                        const Vec3 got = evaluate_position(converted[p], static_cast<float>(u), static_cast<float>(v));
                        const double tol = 2e-5 * scale;
                        ASSERT_NEAR(got.x, want[0] / want[3], tol) << "patch " << p << " mask " << int(masks[p]);
                        ASSERT_NEAR(got.y, want[1] / want[3], tol) << "patch " << p << " mask " << int(masks[p]);
                        ASSERT_NEAR(got.z, want[2] / want[3], tol) << "patch " << p << " mask " << int(masks[p]);
                    }
                if (layout.components == 3) {
                    for (const Vec4& q : converted[p].cp) ASSERT_EQ(q.w, 1.0f);
                }
            }
            const PatchBatch batch = make_batch(converted);
            std::map<std::string, std::size_t> culled;
            expect_same_decisions(src.view, batch.view(), s, culled);
            expect_teeth(culled, grids.size());
        }
    }
}

TEST(PatchSource, BsplineInteriorOfAFlatGridIsItsMiddleAndBoundaryInterpolates) {
    // Uniform grid points x = col, y = row: the interior span covers [1, 2] x [1, 2]; with a
    // boundary at u = 0 the span's edge is the points' column 1 itself.
    std::array<Vec4, 16> g;
    for (int k = 0; k < 16; ++k) {
        const int col = k % 4, row = k / 4;
        g[k] = {float(col), float(row), 0, 1};
    }
    Source src = make_source(std::vector<std::array<Vec4, 16>>{g, g}, {3, 12, 0, false}, PatchBasis::bspline);
    std::vector<std::uint8_t> masks = {0, 8};
    src.view.boundary_mask = masks.data();
    const BezierPatch interior = source_bezier_patch(src.view, 0), boundary = source_bezier_patch(src.view, 1);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            EXPECT_NEAR(interior.cp[4 * j + i].x, 1 + i / 3.0f, 1e-6f);
            EXPECT_NEAR(interior.cp[4 * j + i].y, 1 + j / 3.0f, 1e-6f);
        }
    // Column 0 phantom = 2 col1 - col2 = x 0: the same affine grid, so the same surface.
    for (int k = 0; k < 16; ++k) EXPECT_NEAR(boundary.cp[k].x, interior.cp[k].x, 1e-6f);
    const Vec3 edge = evaluate_position(boundary, 0.0f, 0.5f);
    EXPECT_NEAR(edge.x, 1.0f, 1e-6f);
}

// ---- Gregory ------------------------------------------------------------------------------------

// Gregory points (OpenSubdiv's GREGORY_BASIS order: corner c at 5c: P, E+, E-, F+, F-) of a Bezier
// patch, face points F+ = F- = the Bezier interior point, then F+ and F- moved apart by jitter.
std::array<Vec4, 20> gregory_of(const BezierPatch& b, std::mt19937* rng = nullptr, float jitter = 0) {
    const auto B = [&](int i, int j) { return b.cp[4 * j + i]; };
    std::array<Vec4, 20> g = {B(0, 0), B(1, 0), B(0, 1), B(1, 1), B(1, 1),   // corner (0, 0)
                              B(3, 0), B(3, 1), B(2, 0), B(2, 1), B(2, 1),   // corner (1, 0)
                              B(3, 3), B(2, 3), B(3, 2), B(2, 2), B(2, 2),   // corner (1, 1)
                              B(0, 3), B(0, 2), B(1, 3), B(1, 2), B(1, 2)};  // corner (0, 1)
    if (rng) {
        std::uniform_real_distribution<float> u(-1, 1);
        for (int c = 0; c < 4; ++c)
            for (int f : {3, 4}) {
                Vec4& q = g[5 * c + f];
                q.x += jitter * u(*rng);
                q.y += jitter * u(*rng);
                q.z += jitter * u(*rng);
            }
    }
    return g;
}

// The Gregory patch at (s, t) from its definition: the bicubic Bezier patch whose boundary points
// are the 12 P and E points and whose interior point at corner c blends F+ and F-:
//   (1,1): (s F0+ + t F0-) / (s + t)           (2,1): (t F1+ + (1-s) F1-) / (1 - s + t)
//   (2,2): ((1-s) F2+ + (1-t) F2-) / (2 - s - t)  (1,2): ((1-t) F3+ + s F3-) / (1 + s - t)
// (a zero denominator: the point's Bernstein weight is 0 there; take F+). Cartesian, double.
std::array<double, 3> eval_gregory(const std::array<Vec4, 20>& g, double s, double t) {
    std::array<std::array<double, 4>, 16> bez;
    const auto put = [&](int i, int j, const Vec4& q) { bez[4 * j + i] = {q.x, q.y, q.z, q.w}; };
    const int boundary[12] = {0, 1, 7, 5, 2, 6, 16, 12, 15, 17, 11, 10};
    const int col[12] = {0, 1, 2, 3, 0, 3, 0, 3, 0, 1, 2, 3}, row[12] = {0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 3, 3};
    for (int i = 0; i < 12; ++i) put(col[i], row[i], g[boundary[i]]);
    const auto blend = [&](int i, int j, const Vec4& fp, double a, const Vec4& fm, double b) {
        const double d = a + b;
        if (d <= 0) return put(i, j, fp);
        bez[4 * j + i] = {(a * fp.x + b * fm.x) / d, (a * fp.y + b * fm.y) / d, (a * fp.z + b * fm.z) / d,
                          (a * fp.w + b * fm.w) / d};
    };
    blend(1, 1, g[3], s, g[4], t);
    blend(2, 1, g[8], t, g[9], 1 - s);
    blend(2, 2, g[13], 1 - s, g[14], 1 - t);
    blend(1, 2, g[18], 1 - t, g[19], s);
    const auto bern = [](double x, double w[4]) {
        const double y = 1 - x;
        w[0] = y * y * y;
        w[1] = 3 * x * y * y;
        w[2] = 3 * x * x * y;
        w[3] = x * x * x;
    };
    double bs[4], bt[4];
    bern(s, bs);
    bern(t, bt);
    std::array<double, 4> h{0, 0, 0, 0};
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
            for (int c = 0; c < 4; ++c) h[c] += bs[i] * bt[j] * bez[4 * j + i][c];
    return {h[0] / h[3], h[1] / h[3], h[2] / h[3]};
}

// Clip coordinates of a Cartesian point under the view's object_to_clip, in double.
std::array<double, 4> to_clip(const Mat4& m, const std::array<double, 3>& p) {
    std::array<double, 4> c;
    for (int r = 0; r < 4; ++r)
        c[r] = double(m.at(r, 0)) * p[0] + double(m.at(r, 1)) * p[1] + double(m.at(r, 2)) * p[2] + double(m.at(r, 3));
    return c;
}

// A Gregory patch whose 12 boundary points lie just outside one side of make_scene's frustum
// (side 0..3: left, right, bottom, top) or far behind its depth layer (side 4), and whose 8 face
// points are pulled well inside (towards the eye for side 4): its surface bulges into view, so a
// test that ignored the face points would cull it.
std::array<Vec4, 20> bulging_gregory(std::mt19937& rng, const Scene& s, int side) {
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    const float half_h = std::tan(0.5f), half_w = half_h * float(W) / float(H);  // make_scene's fovy 1.0
    const float d = side == 4 ? 20 + 10 * unit(rng) : 2 + 10 * unit(rng);
    const float size = 0.1f * d * (0.2f + unit(rng));
    Vec3 corner{0.5f * half_w * d * u(rng), 0.5f * half_h * d * u(rng), -d}, pull{0, 0, 0};
    if (side == 0) corner.x = -half_w * d * 1.02f - size, pull = {0.4f * d, 0, 0};
    if (side == 1) corner.x = half_w * d * 1.02f, pull = {-0.4f * d, 0, 0};
    if (side == 2) corner.y = -half_h * d * 1.02f - size, pull = {0, 0.4f * d, 0};
    if (side == 3) corner.y = half_h * d * 1.02f, pull = {0, -0.4f * d, 0};
    if (side == 4) pull = {0, 0, 0.85f * d};
    BezierPatch b;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const Vec3 pv = corner + Vec3{size * i / 3.0f, size * j / 3.0f, 0.1f * size * u(rng)};
            const Vec4 w4 = s.to_world * Vec4{pv.x, pv.y, pv.z, 1};
            b.cp[4 * j + i] = {w4.x, w4.y, w4.z, 1};
        }
    std::array<Vec4, 20> g = gregory_of(b, &rng, 0.05f * size);
    for (int f : {3, 4, 8, 9, 13, 14, 18, 19}) {
        const float k = 0.7f + 0.3f * unit(rng);
        const Vec4 dw = s.to_world * Vec4{k * pull.x, k * pull.y, k * pull.z, 0};
        g[f] = {g[f].x + dw.x, g[f].y + dw.y, g[f].z + dw.z, 1};
    }
    return g;
}

TEST(PatchSource, GregoryNeverCullsAVisibleSampleAndCullsWhatIsOutside) {
    for (ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::reversed}) {
        const Scene s = make_scene(51 + static_cast<std::uint32_t>(depth), depth);
        const bool reversed = is_reversed(depth);
        std::mt19937 rng(61);
        std::vector<std::array<Vec4, 20>> patches;
        for (int i = 0; i < 600; ++i) {
            BezierPatch b;
            const std::array<Vec4, 16> g = random_grid(rng, s, false);
            std::copy(g.begin(), g.end(), b.cp);
            const Vec3 c0 = cartesian(b.cp[0]), c15 = cartesian(b.cp[15]);
            patches.push_back(gregory_of(b, &rng, 0.3f * length(c15 - c0)));
        }
        for (int i = 0; i < 300; ++i) patches.push_back(bulging_gregory(rng, s, i % 5));
        for (const Layout& layout : {Layout{3, 13, 1, true}, Layout{4, 20, 4, false}}) {
            SCOPED_TRACE(layout_name(layout));
            const Source src = make_source(patches, layout, PatchBasis::gregory);
            std::vector<std::uint8_t> frustum(patches.size()), occlusion(patches.size()), back(patches.size(), 9);
            cull_frustum(src.view, nullptr, s.view, frustum.data());
            cull_occlusion(src.view, s.view, s.hiz, occlusion.data());
            cull_backpatch(BackpatchMethod::ptp, src.view, s.view, {PtpRule::pcnt}, back.data());
            std::vector<std::uint8_t> disp_box(patches.size()), fused(patches.size());
            cull_frustum_disp(src.view, nullptr, s.view, disp_box.data());
            cull_fused(src.view, make_fused_setup(s.view, BackPatchCone::ncone, &s.hiz), FusedPlan{}, fused.data());
            std::size_t n_frustum = 0, n_occluded = 0, n_box = 0;
            for (std::size_t p = 0; p < patches.size(); ++p) {
                EXPECT_EQ(back[p], 0) << "ptp never culls a Gregory patch";
                EXPECT_EQ(frustum[p] == 1, occlusion[p] == kHiZFrustumCulled) << "patch " << p;
                // The fused plan frustum, back-patch, Hi-Z: cull_occlusion's decisions.
                EXPECT_EQ(fused[p], occlusion[p]) << "patch " << p;
                // The box holds the hull: what it culls, the hull test culls.
                if (disp_box[p]) {
                    EXPECT_EQ(frustum[p], 1) << "patch " << p;
                }
                n_box += disp_box[p];
                n_frustum += frustum[p];
                n_occluded += occlusion[p] == kHiZOccluded;
                if (occlusion[p] == kHiZVisible) continue;
                for (int a = 0; a <= 24; ++a)
                    for (int b = 0; b <= 24; ++b) {
                        const std::array<double, 4> c =
                            to_clip(s.view.object_to_clip, eval_gregory(patches[p], a / 24.0, b / 24.0));
                        const double x = c[0], y = c[1], z = c[2], w = c[3], e = 1e-5 * std::fabs(w);
                        // 0 <= z <= w in both conventions (near z = 0 forward, z = w reversed).
                        const bool inside =
                            x >= -w + e && x <= w - e && y >= -w + e && y <= w - e && z >= e && z <= w - e;
                        if (!inside) continue;
                        ASSERT_NE(frustum[p], 1)
                            << "patch " << p << " culled by frustum, sample (" << a << ", " << b << ") is inside";
                        // Occluded: the sample's pixel must hold a nearer depth than the sample.
                        const int px = std::min(W - 1, static_cast<int>((x / w * 0.5 + 0.5) * W));
                        const int py = std::min(H - 1, static_cast<int>((y / w * 0.5 + 0.5) * H));
                        const double d = s.depth[static_cast<std::size_t>(py) * W + px], zs = z / w;
                        const bool hidden = reversed ? zs < d - 1e-6 : zs > d + 1e-6;
                        ASSERT_TRUE(hidden) << "patch " << p << " occluded, sample (" << a << ", " << b
                                            << ") is visible at pixel " << px << ", " << py;
                    }
            }
            EXPECT_GT(n_frustum, 10u);
            EXPECT_LT(n_frustum, patches.size());
            EXPECT_GT(n_occluded, 0u);
            EXPECT_GT(n_box, 10u);
        }
    }
}

TEST(PatchSource, GregoryOfABezierPatchDecidesAsTheBezierBatch) {
    // F+ = F- = the Bezier interior points: the 20 points are the 16 of the Bezier patch, so the
    // Gregory path's frustum and occlusion decisions must equal the batch kernels' exactly.
    for (ClipDepth depth :
         {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed, ClipDepth::reversed_infinite}) {
        const Scene s = make_scene(71 + static_cast<std::uint32_t>(depth), depth);
        std::mt19937 rng(81);
        std::vector<BezierPatch> bez;
        std::vector<std::array<Vec4, 20>> greg;
        for (int i = 0; i < 700; ++i) {
            BezierPatch b;
            const std::array<Vec4, 16> g = random_grid(rng, s, i % 4 == 0);
            std::copy(g.begin(), g.end(), b.cp);
            bez.push_back(b);
            greg.push_back(gregory_of(b));
        }
        const PatchBatch batch = make_batch(bez);
        const Source src = make_source(greg, {4, 24, 8, true}, PatchBasis::gregory);
        std::vector<float> disp(bez.size());
        for (std::size_t i = 0; i < disp.size(); ++i) disp[i] = 0.1f * static_cast<float>(i % 5);
        std::vector<std::uint8_t> want(bez.size()), got(bez.size());
        for (const float* d : {static_cast<const float*>(nullptr), static_cast<const float*>(disp.data())}) {
            cull_frustum(batch.view(), d, s.view, want.data());
            cull_frustum(src.view, d, s.view, got.data());
            EXPECT_EQ(want, got);
            EXPECT_GT(std::count(want.begin(), want.end(), 1), 0);
        }
        cull_occlusion(batch.view(), s.view, s.hiz, want.data());
        cull_occlusion(src.view, s.view, s.hiz, got.data());
        EXPECT_EQ(want, got);
        EXPECT_GT(std::count(want.begin(), want.end(), kHiZOccluded), 0);
        cull_occlusion_parallel(src.view, s.view, s.hiz, got.data());
        EXPECT_EQ(want, got);
        // frustum-disp: the box of the 20 points is the box of the 16.
        for (const float* d : {static_cast<const float*>(nullptr), static_cast<const float*>(disp.data())}) {
            cull_frustum_disp(batch.view(), d, s.view, want.data());
            cull_frustum_disp(src.view, d, s.view, got.data());
            EXPECT_EQ(want, got);
            EXPECT_GT(std::count(want.begin(), want.end(), 1), 0);
            cull_frustum_disp_parallel(src.view, d, s.view, got.data());
            EXPECT_EQ(want, got);
        }
        // The Gregory cone of such a patch has the tangent cone's vectors (the face-point
        // differences are 0 and skipped, the others repeat the Bezier net's), so its cone test is
        // tcone's on the batch, for the cone methods (ptp never culls a Gregory patch).
        const std::size_t polynomial = static_cast<std::size_t>(
            std::count_if(bez.begin(), bez.end(), [](const BezierPatch& b) { return b.cp[0].w == 1.0f; }));
        cull_backpatch(BackpatchMethod::tcone, batch.view(), s.view, {}, want.data());
        EXPECT_GT(std::count(want.begin(), want.end(), 1), 0);
        for (BackpatchMethod id : {BackpatchMethod::tcone, BackpatchMethod::ncone}) {
            cull_backpatch(id, src.view, s.view, {}, got.data());
            EXPECT_EQ(want, got) << backpatch_method_name(id);
            cull_backpatch_parallel(id, src.view, s.view, {}, got.data());
            EXPECT_EQ(want, got) << backpatch_method_name(id) << " parallel";
        }
        EXPECT_LT(polynomial, bez.size()) << "some rational patches, which no cone culls";
        cull_backpatch(BackpatchMethod::ptp, src.view, s.view, {}, got.data());
        EXPECT_EQ(std::count(got.begin(), got.end(), 0), static_cast<std::ptrdiff_t>(got.size()));
        // The fused kernel with the tcone stage: the batch's decisions, in every plan.
        const FusedCullSetup setup = make_fused_setup(s.view, BackPatchCone::tcone, &s.hiz);
        FusedPlan plans[6];
        const int count = fused_plans_of(7, plans);
        for (int k = 0; k < count; ++k) {
            cull_fused_simd(batch.view(), setup, plans[k], want.data());
            cull_fused(src.view, setup, plans[k], got.data());
            EXPECT_EQ(want, got) << fused_plan_name(plans[k]);
            EXPECT_GT(std::count(want.begin(), want.end(), kFusedOccluded), 0);
            EXPECT_GT(std::count(want.begin(), want.end(), kFusedBackPatchCulled), 0);
            cull_fused_parallel(src.view, setup, plans[k], got.data());
            EXPECT_EQ(want, got) << fused_plan_name(plans[k]) << " parallel";
        }
    }
}

// The Gregory cone (tcone and ncone over a Gregory source) against the surface: no culled patch
// has a sample, on a 25 x 25 grid, whose normal faces the eye. The patches include face points
// pulled far apart along the normal and along the tangents, where the interior blend's own
// derivative (the cone's last four vectors per direction) turns the normal.
TEST(PatchSource, GregoryConeNeverCullsAFacingSample) {
    std::size_t culled_total = 0, tested_total = 0;
    for (ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed}) {
        const Scene s = make_scene(131 + static_cast<std::uint32_t>(depth), depth);
        ASSERT_TRUE(s.view.has_eye);
        std::mt19937 rng(141);
        std::uniform_real_distribution<float> u(-1, 1);
        std::vector<std::array<Vec4, 20>> patches;
        for (int i = 0; i < 1500; ++i) {
            BezierPatch b;
            const std::array<Vec4, 16> g = random_grid(rng, s, false);
            std::copy(g.begin(), g.end(), b.cp);
            const Vec3 c0 = cartesian(b.cp[0]), c3 = cartesian(b.cp[3]), c12 = cartesian(b.cp[12]);
            const float size = length(c3 - c0);
            std::array<Vec4, 20> q = gregory_of(b, &rng, (i % 4) * 0.1f * size);
            if (i % 3 == 0) {
                // F+ and F- of each corner pulled apart along the patch normal and a tangent.
                const Vec3 n = normalize(cross(c3 - c0, c12 - c0)), t = normalize(c3 - c0);
                for (int c = 0; c < 4; ++c) {
                    const float a = 0.4f * size * u(rng), k = 0.4f * size * u(rng);
                    Vec4& fp = q[5 * c + 3];
                    Vec4& fm = q[5 * c + 4];
                    fp = {fp.x + a * n.x + k * t.x, fp.y + a * n.y + k * t.y, fp.z + a * n.z + k * t.z, 1};
                    fm = {fm.x - a * n.x - k * t.x, fm.y - a * n.y - k * t.y, fm.z - a * n.z - k * t.z, 1};
                }
            }
            patches.push_back(q);
        }
        const Source src = make_source(patches, {3, 16, 4, true}, PatchBasis::gregory);
        std::vector<std::uint8_t> tcone(patches.size()), ncone(patches.size()), fused(patches.size());
        cull_backpatch(BackpatchMethod::tcone, src.view, s.view, {}, tcone.data());
        cull_backpatch(BackpatchMethod::ncone, src.view, s.view, {}, ncone.data());
        EXPECT_EQ(tcone, ncone) << "one Gregory cone for both cone methods";
        FusedPlan back_only;
        back_only.stages[0] = FusedStage::backpatch;
        back_only.count = 1;
        cull_fused(src.view, make_fused_setup(s.view, BackPatchCone::ncone, nullptr), back_only, fused.data());
        const Vec3 e = s.view.eye;
        std::size_t culled = 0;
        for (std::size_t p = 0; p < patches.size(); ++p) {
            EXPECT_EQ(fused[p], tcone[p] ? kFusedBackPatchCulled : kFusedVisible) << "patch " << p;
            if (!tcone[p]) continue;
            ++culled;
            constexpr double h = 1e-5;
            for (int a = 0; a <= 24; ++a)
                for (int b = 0; b <= 24; ++b) {
                    const double u0 = a / 24.0, v0 = b / 24.0;
                    const double ul = std::max(0.0, u0 - h), uh = std::min(1.0, u0 + h);
                    const double vl = std::max(0.0, v0 - h), vh = std::min(1.0, v0 + h);
                    const auto pu1 = eval_gregory(patches[p], uh, v0), pu0 = eval_gregory(patches[p], ul, v0);
                    const auto pv1 = eval_gregory(patches[p], u0, vh), pv0 = eval_gregory(patches[p], u0, vl);
                    const auto pt = eval_gregory(patches[p], u0, v0);
                    double su[3], sv[3], to_eye[3];
                    for (int c = 0; c < 3; ++c) {
                        su[c] = (pu1[c] - pu0[c]) / (uh - ul);
                        sv[c] = (pv1[c] - pv0[c]) / (vh - vl);
                    }
                    to_eye[0] = e.x - pt[0];
                    to_eye[1] = e.y - pt[1];
                    to_eye[2] = e.z - pt[2];
                    const double n[3] = {su[1] * sv[2] - su[2] * sv[1], su[2] * sv[0] - su[0] * sv[2],
                                         su[0] * sv[1] - su[1] * sv[0]};
                    const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                    const double ne = std::sqrt(to_eye[0] * to_eye[0] + to_eye[1] * to_eye[1] + to_eye[2] * to_eye[2]);
                    const double facing = n[0] * to_eye[0] + n[1] * to_eye[1] + n[2] * to_eye[2];
                    ASSERT_LE(facing, 1e-6 * nn * ne) << clip_depth_name(depth) << ": patch " << p
                                                      << " culled, its sample (" << a << ", " << b << ") faces the eye";
                }
        }
        EXPECT_GT(culled, patches.size() / 50) << clip_depth_name(depth);
        culled_total += culled;
        tested_total += patches.size();
    }
    EXPECT_LT(culled_total, tested_total);
}

TEST(PatchSource, GregoryOutsideOrHiddenIsCulledAndNonFiniteIsNot) {
    const Scene s = make_scene(91, ClipDepth::zero_to_one);
    const auto placed = [&](float x, float y, float z) {
        BezierPatch b;
        for (int k = 0; k < 16; ++k) {
            const int col = k % 4, row = k / 4;
            const Vec4 w4 = s.to_world * Vec4{x + 0.1f * float(col), y + 0.1f * float(row), z, 1};
            b.cp[k] = {w4.x, w4.y, w4.z, 1};
        }
        return b;
    };
    std::mt19937 rng(3);
    std::vector<std::array<Vec4, 20>> greg = {gregory_of(placed(-40, 0, -5), &rng, 0.05f),  // far left: culled
                                              gregory_of(placed(0, 0, -5), &rng, 0.05f)};   // in view: kept
    // One far-left copy per point with a NaN or infinite x: never culled.
    for (int k = 0; k < 20; ++k)
        for (float bad : {kNaN, std::numeric_limits<float>::infinity()}) {
            std::array<Vec4, 20> g = greg[0];
            g[k].x = bad;
            greg.push_back(g);
        }
    const Source src = make_source(greg, {4, 16, 0, false}, PatchBasis::gregory);
    std::vector<std::uint8_t> culled(greg.size()), decision(greg.size());
    cull_frustum(src.view, nullptr, s.view, culled.data());
    cull_occlusion(src.view, s.view, s.hiz, decision.data());
    EXPECT_EQ(culled[0], 1);
    EXPECT_EQ(decision[0], kHiZFrustumCulled);
    EXPECT_EQ(culled[1], 0);
    for (std::size_t i = 2; i < greg.size(); ++i) {
        EXPECT_EQ(culled[i], 0) << "copy " << i;
        EXPECT_EQ(decision[i], kHiZVisible) << "copy " << i;
    }
    cull_frustum_disp(src.view, nullptr, s.view, culled.data());
    cull_fused(src.view, make_fused_setup(s.view, BackPatchCone::tcone, &s.hiz), FusedPlan{}, decision.data());
    EXPECT_EQ(culled[0], 1);
    EXPECT_EQ(decision[0], kFusedFrustumCulled);
    EXPECT_EQ(culled[1], 0);
    for (std::size_t i = 2; i < greg.size(); ++i) {
        EXPECT_EQ(culled[i], 0) << "frustum-disp, copy " << i;
        EXPECT_EQ(decision[i], kFusedVisible) << "fused, copy " << i;
    }
    // Behind a wall at the near distance: occluded.
    std::vector<float> wall(static_cast<std::size_t>(W) * H, 0.5f);  // window depth 0.5: about 0.2 away
    HiZPyramid hiz;
    hiz.build(wall.data(), W, H, ClipDepth::zero_to_one);
    const Source one = make_source(std::vector<std::array<Vec4, 20>>{greg[1]}, {3, 12, 0, false}, PatchBasis::gregory);
    std::uint8_t d = 9;
    cull_occlusion(one.view, s.view, hiz, &d);
    EXPECT_EQ(d, kHiZOccluded);
}

// The parallel entries over several grains and a ragged tail: every range reads its own slice of
// the indices, masks and displacement bounds and writes its own slice of the output, as the
// single-threaded entry does (Bezier, masked B-spline and Gregory sources, indexed and not).
TEST(PatchSource, ParallelEntriesOverManyRangesDecideAsTheSingleThreadedOnes) {
    const Scene s = make_scene(111, ClipDepth::reversed);
    std::mt19937 rng(13);
    const std::size_t count = 2 * kParallelGrain + 37;  // three ranges of up to kParallelGrain
    std::vector<std::array<Vec4, 16>> grids;
    std::vector<std::array<Vec4, 20>> gregory;
    std::vector<std::uint8_t> masks;
    for (std::size_t i = 0; i < count; ++i) {
        grids.push_back(random_grid(rng, s, i % 3 == 0));
        masks.push_back(static_cast<std::uint8_t>(rng() % 16));
        if (i % 211 == 7) grids.back()[5].y = kNaN;
    }
    for (std::size_t i = 0; i < count; ++i) {
        BezierPatch b;
        std::copy(grids[i].begin(), grids[i].end(), b.cp);
        gregory.push_back(gregory_of(b));
    }
    std::vector<float> disp(count);
    for (std::size_t i = 0; i < count; ++i) disp[i] = 0.03f * static_cast<float>(i % 5);
    const FusedCullSetup setup = make_fused_setup(s.view, BackPatchCone::ncone, &s.hiz);
    std::vector<std::uint8_t> want(count + 1, 0xAB), got(count + 1, 0xAB);
    for (bool indexed : {true, false}) {
        Source bezier = make_source(grids, {4, 24, 4, indexed}, PatchBasis::bezier);
        Source bspline = make_source(grids, {3, 16, 0, indexed}, PatchBasis::bspline);
        bspline.masks = masks;
        bspline.view.boundary_mask = bspline.masks.data();
        Source greg = make_source(gregory, {3, 12, 0, indexed}, PatchBasis::gregory);
        for (const PatchSourceView* v : {&bezier.view, &bspline.view, &greg.view}) {
            const std::string name =
                std::string(indexed ? "indexed " : "consecutive ") + (v->basis == PatchBasis::bezier    ? "bezier"
                                                                      : v->basis == PatchBasis::bspline ? "bspline"
                                                                                                        : "gregory");
            const auto check = [&](const std::string& what) {
                EXPECT_EQ(got[count], 0xAB) << name << ", " << what << ": wrote past count";
                std::size_t differ = 0, culled = 0;
                for (std::size_t i = 0; i < count; ++i) {
                    differ += got[i] != want[i];
                    culled += want[i] != 0;
                }
                EXPECT_EQ(differ, 0u) << name << ", " << what;
                if (!(v->basis == PatchBasis::gregory && what == "ptp")) {
                    EXPECT_GT(culled, 0u) << name << ", " << what;
                }
            };
            cull_frustum(*v, disp.data(), s.view, want.data());
            cull_frustum_parallel(*v, disp.data(), s.view, got.data());
            check("frustum");
            cull_frustum_disp(*v, disp.data(), s.view, want.data());
            cull_frustum_disp_parallel(*v, disp.data(), s.view, got.data());
            check("frustum-disp");
            cull_backpatch(BackpatchMethod::ptp, *v, s.view, {}, want.data());
            cull_backpatch_parallel(BackpatchMethod::ptp, *v, s.view, {}, got.data());
            check("ptp");
            cull_occlusion(*v, s.view, s.hiz, want.data());
            cull_occlusion_parallel(*v, s.view, s.hiz, got.data());
            check("occlusion");
            cull_fused(*v, setup, FusedPlan{}, want.data());
            cull_fused_parallel(*v, setup, FusedPlan{}, got.data());
            check("fused");
        }
    }
}

// ---- bad views ----------------------------------------------------------------------------------

void expect_refused(const PatchSourceView& v, const std::string& message, const Scene& s) {
    std::vector<std::uint8_t> out(std::max<std::size_t>(v.count, 1), 0xAB);
    const FusedCullSetup setup = make_fused_setup(s.view, BackPatchCone::tcone, &s.hiz);
    for (int entry = 0; entry < 10; ++entry) {
        try {
            if (entry == 0) cull_frustum(v, nullptr, s.view, out.data());
            if (entry == 1) cull_backpatch(BackpatchMethod::tcone, v, s.view, {}, out.data());
            if (entry == 2) cull_occlusion(v, s.view, s.hiz, out.data());
            if (entry == 3) cull_frustum_disp(v, nullptr, s.view, out.data());
            if (entry == 4) cull_fused(v, setup, FusedPlan{}, out.data());
            if (entry == 5) cull_frustum_parallel(v, nullptr, s.view, out.data());
            if (entry == 6) cull_backpatch_parallel(BackpatchMethod::tcone, v, s.view, {}, out.data());
            if (entry == 7) cull_occlusion_parallel(v, s.view, s.hiz, out.data());
            if (entry == 8) cull_frustum_disp_parallel(v, nullptr, s.view, out.data());
            if (entry == 9) cull_fused_parallel(v, setup, FusedPlan{}, out.data());
            ADD_FAILURE() << "no Error for: " << message;
        } catch (const Error& e) {
            const std::string what = e.what();
            const char* name[10] = {"cull_frustum: ",
                                    "cull_backpatch: ",
                                    "cull_occlusion: ",
                                    "cull_frustum_disp: ",
                                    "cull_fused: ",
                                    "cull_frustum_parallel: ",
                                    "cull_backpatch_parallel: ",
                                    "cull_occlusion_parallel: ",
                                    "cull_frustum_disp_parallel: ",
                                    "cull_fused_parallel: "};
            EXPECT_EQ(what.rfind(name[entry], 0), 0u) << what;
            EXPECT_NE(what.find(message), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos);
        }
        for (std::uint8_t b : out) EXPECT_EQ(b, 0xAB) << "wrote before refusing";
    }
}

TEST(PatchSource, BadViewsAreRefusedWithAMessage) {
    const Scene s = make_scene(101, ClipDepth::zero_to_one);
    std::mt19937 rng(1);
    std::vector<std::array<Vec4, 16>> grids;
    grids.reserve(3);
    for (int i = 0; i < 3; ++i) grids.push_back(random_grid(rng, s, false));
    Source src = make_source(grids, {3, 16, 4, true}, PatchBasis::bezier);
    PatchSourceView v = src.view;
    v.points.components = 2;
    expect_refused(v, "points.components is 2", s);
    v = src.view;
    v.points.components = 5;
    expect_refused(v, "points.components is 5; it must be 3", s);
    v = src.view;
    v.points.stride_bytes = 15;  // offset 4 + 12 bytes
    expect_refused(v, "points.stride_bytes is 15, smaller than offset_bytes (4) + 12 bytes", s);
    v = src.view;
    v.points.data = nullptr;
    expect_refused(v, "points.data is null for 3 patches", s);
    v = src.view;
    src.indices[16 + 5] = static_cast<std::uint32_t>(v.points.point_count);
    expect_refused(v, "patch 1, point 5: index " + std::to_string(v.points.point_count) + " is past points.point_count",
                   s);
    src.indices[16 + 5] = 0;
    v.indices = nullptr;
    v.points.point_count = 47;
    expect_refused(v, "3 patches need 3 x 16 points, but points.point_count is 47", s);
    v = src.view;
    std::vector<std::uint8_t> masks = {0, 3, 0};
    v.boundary_mask = masks.data();
    expect_refused(v, "boundary_mask is for bspline patches only, and the basis is bezier", s);
    v.basis = PatchBasis::bspline;
    masks[2] = 16;
    expect_refused(v, "boundary_mask[2] is 16", s);
    masks[2] = 15;
    std::vector<std::uint8_t> out(3);
    EXPECT_NO_THROW(cull_frustum(v, nullptr, s.view, out.data()));
    // A phantom slot's index is not checked (mask 3: row 0 and column 3 of patch 1).
    src.indices[16 + 3] = 0xFFFFFFFFu;
    EXPECT_NO_THROW(cull_frustum(v, nullptr, s.view, out.data()));
    src.indices[16 + 5] = 0xFFFFFFFFu;  // a real slot
    expect_refused(v, "patch 1, point 5: index 4294967295", s);
    // Gregory without indices: 20 points a patch.
    v = src.view;
    v.basis = PatchBasis::gregory;
    v.indices = nullptr;
    v.points.point_count = 59;
    expect_refused(v, "3 patches need 3 x 20 points", s);
    // An unknown back-patch method, and an empty view (nothing to check, nothing written).
    EXPECT_THROW(cull_backpatch(static_cast<BackpatchMethod>(1000), src.view, s.view, {}, out.data()), Error);
    PatchSourceView empty;
    EXPECT_NO_THROW(cull_frustum(empty, nullptr, s.view, nullptr));
    // A pyramid of the other direction.
    HiZPyramid reversed;
    std::vector<float> d(16, 0.0f);
    reversed.build(d.data(), 4, 4, ClipDepth::reversed);
    EXPECT_THROW(cull_occlusion(src.view, s.view, reversed, out.data()), Error);
    // The fused kernel's own inputs: a plan valid_fused_plan refuses, occlusion without a pyramid
    // or with one never built or of the other direction; without occlusion no pyramid is needed.
    src.indices[16 + 3] = src.indices[16 + 5] = 0;  // the view is good again
    FusedCullSetup setup = make_fused_setup(s.view, BackPatchCone::tcone, &s.hiz);
    FusedPlan bad;
    bad.stages[0] = FusedStage::occlusion;
    bad.stages[1] = FusedStage::frustum;
    bad.count = 2;
    const auto fused_error = [&](const FusedCullSetup& st, const FusedPlan& plan) -> std::string {
        try {
            cull_fused(src.view, st, plan, out.data());
        } catch (const Error& e) {
            return e.what();
        }
        return "";
    };
    EXPECT_EQ(fused_error(setup, bad), "cull_fused: invalid plan HF");
    setup.hiz = nullptr;
    EXPECT_EQ(fused_error(setup, FusedPlan{}), "cull_fused: the plan has occlusion but setup.hiz is null");
    FusedPlan fb;
    fb.count = 2;
    EXPECT_EQ(fused_error(setup, fb), "");
    HiZPyramid unbuilt;
    setup.hiz = &unbuilt;
    EXPECT_NE(fused_error(setup, FusedPlan{}).find("never built"), std::string::npos);
    setup.hiz = &reversed;
    EXPECT_NE(fused_error(setup, FusedPlan{}).find("reversed"), std::string::npos);
    EXPECT_THROW(cull_fused_parallel(src.view, setup, FusedPlan{}, out.data()), Error);
}

}  // namespace
}  // namespace patchcull
