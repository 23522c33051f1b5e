// GPU displaced-patch culling (patchcull/gl/gl_displaced.h) against the CPU kernels of
// patchcull/core/displaced_bounds.h: on the same patches, ranges, views and Hi-Z pyramid, every one of
// the 6 combinations {oobb, caf} x {full, acon, con} must give the same frustum decisions
// (cull_displaced_frustum), the same occlusion decisions (cull_displaced_occlusion) and the same
// bound values bit for bit (compute_displaced_bounds). The scene mixes the split teapot (degenerate
// patches included), random sheets at many scales, collapsed edges, point clouds, rational
// patches and a few invalid ones (NaN, inf, weight <= 0); the views are whole-scene (`contain`),
// free (camera inside the scene, near planes cutting patches), an eye next to a patch (bounds
// crossing the eye plane) and a non-rigid model matrix. The depth buffer holds random occluder
// rectangles at depths around the patches' own, so that many patches are occluded.
// Teeth: a GPU run on deliberately different input (halved ranges, another cone, another bound)
// must disagree with the CPU on real input.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/cone_test_patches.h"
#include "gl/gl_test_util.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/hiz.h"
#include "patchcull/gl/gl_displaced.h"

namespace patchcull::gl {
namespace {

using cone_test::D3;
using cone_test::PatchGen;

constexpr DisplacedBoundKind kBounds[] = {DisplacedBoundKind::oobb, DisplacedBoundKind::caf};
constexpr NormalConeKind kCones[] = {NormalConeKind::full, NormalConeKind::acon, NormalConeKind::con};
constexpr int kScreenW = 160, kScreenH = 96;

DisplacedCuller& culler() {
    static DisplacedCuller c(test::context());
    return c;
}

std::string combo_name(DisplacedBoundKind b, NormalConeKind c) {
    return std::string(displaced_bound_name(b)) + "/" + normal_cone_name(c);
}

// ---- the scene ---------------------------------------------------------------------------------------

struct Scene {
    std::vector<BezierPatch> patches;
    std::vector<DisplacementRange> ranges;
    Bounds bounds;  // of the teapot and the sheets (not of the invalid patches)
};

double patch_size(const BezierPatch& p) {
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (const Vec4& c : p.cp) {
        const Vec3 q = cartesian(c);
        const float v[3] = {q.x, q.y, q.z};
        for (int i = 0; i < 3; ++i) {
            lo[i] = std::min(lo[i], v[i]);
            hi[i] = std::max(hi[i], v[i]);
        }
    }
    return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-6f});
}

/// Random ranges relative to the patch size: two-sided, one-sided, zero, -0 / +0, not holding 0
/// (widened to hold it), and a few large ones (the bound then reaches the eye plane).
DisplacementRange random_range(std::mt19937& rng, double size) {
    std::uniform_real_distribution<double> unit(0, 1);
    auto magnitude = [&] { return float(size * std::pow(10.0, -3 + 3.0 * unit(rng))); };
    switch (rng() % 10) {
        case 0:
            return {};
        case 1:
            return {-0.0f, 0.0f};
        case 2:
            return {0.0f, magnitude()};
        case 3:
            return {-magnitude(), 0.0f};
        case 4:
            return {0.5f * magnitude(), magnitude()};  // excludes 0: widened to [0, d_max]
        case 5:
            return {-magnitude() * 20.0f, magnitude() * 20.0f};
        default:
            return {-magnitude(), magnitude()};
    }
}

Scene make_scene(unsigned seed, int sheets) {
    Scene s;
    // The teapot split twice (512 patches, its degenerate lid and bottom patches included), at the
    // origin; its size is about 6 x 4 x 3.
    s.patches = test::split_teapot(2);
    PatchGen gen(seed);
    std::mt19937 rng(seed * 3 + 1);
    for (int i = 0; i < sheets; ++i) {
        const double size = std::pow(10.0, gen.uniform(-1.7, -0.2));
        const D3 centre{gen.uniform(-4, 4), gen.uniform(-4, 4), gen.uniform(-2, 4)};
        const int kind = gen.integer(0, 19);
        BezierPatch p = kind < 13   ? gen.sheet(std::pow(10.0, gen.uniform(-3, -0.5)), size, centre)
                        : kind < 15 ? gen.sheet(gen.uniform(0.3, 1.5), size, centre)
                        : kind < 18 ? PatchGen::collapse(gen.sheet(0.1, size, centre), kind == 15)
                                    : gen.cloud(size, centre);
        if (rng() % 10 == 0) {  // rational: no cone, the bounds fall back to full
            std::uniform_real_distribution<float> w(0.5f, 2.0f);
            for (Vec4& c : p.cp) c = c * w(rng);
        }
        s.patches.push_back(p);
    }
    std::vector<Vec3> points;
    for (const BezierPatch& p : s.patches)
        for (const Vec4& c : p.cp) points.push_back(cartesian(c));
    s.bounds = compute_bounds(points);
    // Invalid inputs: never culled on either side.
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    BezierPatch bad = s.patches[600];
    bad.cp[5].y = nan;
    s.patches.push_back(bad);
    bad = s.patches[601];
    bad.cp[9].x = inf;
    s.patches.push_back(bad);
    bad = s.patches[602];
    bad.cp[0].w = 0.0f;
    s.patches.push_back(bad);
    bad = s.patches[603];
    bad.cp[15] = bad.cp[15] * -1.0f;  // weight -1
    s.patches.push_back(bad);
    for (const BezierPatch& p : s.patches) s.ranges.push_back(random_range(rng, patch_size(p)));
    s.ranges[s.patches.size() - 5].d_max = nan;  // a non-finite range on a valid patch
    return s;
}

Mat4 random_model(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-1, 1);
    Mat4 m;
    m.at(0, 0) = 1.5f + 0.5f * u(rng);
    m.at(1, 1) = 1.0f + 0.5f * u(rng);
    m.at(2, 2) = 0.6f + 0.3f * u(rng);
    m.at(0, 1) = 0.4f * u(rng);
    m.at(1, 2) = 0.4f * u(rng);
    m.at(0, 3) = u(rng);
    return m;
}

struct TestView {
    std::string name;
    DisplacedCullView view;
};

/// contain, free (camera inside the scene), an eye right next to a patch (bounds across the eye
/// plane), and a non-rigid model matrix.
std::vector<TestView> make_views(const Scene& s, unsigned seed) {
    std::vector<TestView> views;
    const float aspect = float(kScreenW) / float(kScreenH);
    ViewGenerator contain(s.bounds, ViewMode::contain, seed, aspect);
    ViewGenerator free_views(s.bounds, ViewMode::free, seed + 1, aspect);
    for (int i = 0; i < 2; ++i) {
        const Camera c = contain.next();
        views.push_back({"contain " + std::to_string(i),
                         make_displaced_cull_view(c.view(), c.projection(), ClipDepth::zero_to_one)});
    }
    for (int i = 0; i < 2; ++i) {
        const Camera c = free_views.next();
        views.push_back(
            {"free " + std::to_string(i), make_displaced_cull_view(c.view(), c.projection(), ClipDepth::zero_to_one)});
    }
    {
        // The eye 0.02 in front of a teapot patch's centre, looking across the scene.
        Camera c;
        const BezierPatch& p = s.patches[200];
        const Vec3 centre = (cartesian(p.cp[5]) + cartesian(p.cp[10])) * 0.5f;
        c.eye = centre + Vec3{0.0f, 0.0f, 0.02f};
        c.target = s.bounds.center();
        c.up = {0, 0, 1};
        c.aspect = aspect;
        c.z_near = 0.005f;
        c.z_far = 40.0f;
        views.push_back({"eye close", make_displaced_cull_view(c.view(), c.projection(), ClipDepth::zero_to_one)});
    }
    {
        std::mt19937 rng(seed);
        const Camera c = contain.next();
        views.push_back({"non-rigid model", make_displaced_cull_view(c.view() * random_model(rng), c.projection(),
                                                                     ClipDepth::zero_to_one)});
    }
    for (const TestView& v : views) EXPECT_TRUE(v.view.valid) << v.name;
    return views;
}

/// Occluder rectangles at depths between the 20% and 80% quantiles of the patches' own nearest
/// depths (caf / full bounds), over a far background: many patches end up behind them.
HiZPyramid make_hiz(const Scene& s, const DisplacedCullView& view, std::mt19937& rng) {
    std::vector<DisplacedBound> b(s.patches.size());
    const PatchBatch batch = test::unchecked_batch(s.patches);
    compute_displaced_bounds(batch.view(), s.ranges.data(), DisplacedBoundKind::caf, NormalConeKind::full, view,
                             b.data());
    std::vector<float> near;
    for (const DisplacedBound& x : b)
        if (x.status == kDisplacedBoundProjected && x.depth_near >= 0.0f && x.depth_near <= 1.0f)
            near.push_back(x.depth_near);
    std::sort(near.begin(), near.end());
    const float lo = near.empty() ? 0.5f : near[near.size() / 5], hi = near.empty() ? 0.9f : near[near.size() * 4 / 5];
    std::vector<float> depth(static_cast<std::size_t>(kScreenW) * kScreenH, 1.0f);
    std::uniform_real_distribution<float> unit(0, 1);
    for (int r = 0; r < 6; ++r) {
        const int x0 = static_cast<int>(rng() % kScreenW), y0 = static_cast<int>(rng() % kScreenH);
        const int w = kScreenW / 4 + static_cast<int>(rng() % (kScreenW / 2));
        const int h = kScreenH / 4 + static_cast<int>(rng() % (kScreenH / 2));
        const float z = lo + (hi - lo) * unit(rng);
        for (int y = y0; y < std::min(kScreenH, y0 + h); ++y)
            for (int x = x0; x < std::min(kScreenW, x0 + w); ++x) {
                float& d = depth[static_cast<std::size_t>(y) * kScreenW + x];
                d = std::min(d, z);
            }
    }
    HiZPyramid hiz;
    hiz.build(depth.data(), kScreenW, kScreenH);
    return hiz;
}

bool same_bits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

bool same_bound(const DisplacedBound& a, const DisplacedBound& b) {
    return a.status == b.status && same_bits(a.ndc_xmin, b.ndc_xmin) && same_bits(a.ndc_xmax, b.ndc_xmax) &&
           same_bits(a.ndc_ymin, b.ndc_ymin) && same_bits(a.ndc_ymax, b.ndc_ymax) &&
           same_bits(a.depth_near, b.depth_near) && same_bits(a.depth_far, b.depth_far);
}

std::string describe(const DisplacedBound& b) {
    char text[200];
    std::snprintf(text, sizeof text, "status %d rect [%.9g, %.9g] x [%.9g, %.9g] depth [%.9g, %.9g]", int(b.status),
                  b.ndc_xmin, b.ndc_xmax, b.ndc_ymin, b.ndc_ymax, b.depth_near, b.depth_far);
    return text;
}

/// Counts per combination over all views.
struct Tally {
    std::size_t decisions = 0, frustum_equal = 0, occlusion_equal = 0, bounds_equal = 0;
    std::size_t frustum_culled = 0, occluded = 0, projected = 0, unprojectable = 0, outside_plane = 0, invalid = 0;
};

TEST(DisplacedGpu, DecisionsAndBoundsEqualTheCpu) {
    const Scene s = make_scene(11, 1500);
    const PatchBatch batch = test::unchecked_batch(s.patches);
    const std::size_t n = s.patches.size();
    DisplacedCuller& gpu = culler();
    gpu.set_patches(s.patches, s.ranges);
    ASSERT_EQ(gpu.patch_count(), n);
    std::mt19937 rng(5);
    Tally tally[6];
    for (const TestView& tv : make_views(s, 21)) {
        const HiZPyramid hiz = make_hiz(s, tv.view, rng);
        gpu.set_hiz(hiz);
        int index = 0;
        for (DisplacedBoundKind b : kBounds)
            for (NormalConeKind c : kCones) {
                const std::string where = combo_name(b, c) + ", view " + tv.name;
                Tally& t = tally[index++];
                std::vector<std::uint8_t> cpu_frustum(n), cpu_occlusion(n), gpu_frustum, gpu_occlusion;
                std::vector<DisplacedBound> cpu_bounds(n), gpu_bounds;
                cull_displaced_frustum(batch.view(), s.ranges.data(), b, c, tv.view, cpu_frustum.data());
                cull_displaced_occlusion(batch.view(), s.ranges.data(), b, c, tv.view, hiz, cpu_occlusion.data());
                compute_displaced_bounds(batch.view(), s.ranges.data(), b, c, tv.view, cpu_bounds.data());
                gpu.cull_frustum(b, c, tv.view, &gpu_frustum);
                gpu.cull_occlusion(b, c, tv.view, &gpu_occlusion, &gpu_bounds);
                // The flag words of the last call are reason bits only: kCullFrustum, kCullOcclusion or 0.
                const std::vector<std::uint32_t> words = gpu.read_flag_words();
                ASSERT_EQ(words.size(), n);
                ASSERT_EQ(gpu_frustum.size(), n);
                ASSERT_EQ(gpu_occlusion.size(), n);
                ASSERT_EQ(gpu_bounds.size(), n);
                std::size_t reported = 0;
                for (std::size_t p = 0; p < n; ++p) {
                    ++t.decisions;
                    EXPECT_TRUE(words[p] == 0 || words[p] == kCullFrustum || words[p] == kCullOcclusion)
                        << where << " patch " << p << ": word " << words[p];
                    t.frustum_equal += cpu_frustum[p] == gpu_frustum[p];
                    t.occlusion_equal += cpu_occlusion[p] == gpu_occlusion[p];
                    t.bounds_equal += same_bound(cpu_bounds[p], gpu_bounds[p]);
                    t.frustum_culled += cpu_frustum[p] != 0;
                    t.occluded += cpu_occlusion[p] == kHiZOccluded;
                    t.projected += cpu_bounds[p].status == kDisplacedBoundProjected;
                    t.outside_plane += cpu_bounds[p].status == kDisplacedBoundOutsidePlane;
                    t.unprojectable += cpu_bounds[p].status == kDisplacedBoundUnprojectable;
                    t.invalid += cpu_bounds[p].status == kDisplacedBoundInvalid;
                    // Frustum decisions of the two passes agree on each side (frustum first).
                    EXPECT_EQ(cpu_frustum[p] != 0, cpu_occlusion[p] == kHiZFrustumCulled) << where << " patch " << p;
                    const bool differs = cpu_frustum[p] != gpu_frustum[p] || cpu_occlusion[p] != gpu_occlusion[p] ||
                                         !same_bound(cpu_bounds[p], gpu_bounds[p]);
                    if (differs && reported++ < 3)  // the first few in detail; the tallies below count them all
                        ADD_FAILURE() << where << " patch " << p << ": frustum cpu " << int(cpu_frustum[p]) << " gpu "
                                      << int(gpu_frustum[p]) << ", occlusion cpu " << int(cpu_occlusion[p]) << " gpu "
                                      << int(gpu_occlusion[p]) << "\n  cpu " << describe(cpu_bounds[p]) << "\n  gpu "
                                      << describe(gpu_bounds[p]);
                }
            }
    }
    int index = 0;
    for (DisplacedBoundKind b : kBounds)
        for (NormalConeKind c : kCones) {
            const Tally& t = tally[index++];
            std::printf(
                "[ displaced ] %-9s %zu decisions: frustum equal %zu (culled %zu), occlusion equal %zu "
                "(occluded %zu), bounds bit-identical %zu; projected %zu, outside-plane %zu, "
                "unprojectable %zu, invalid %zu\n",
                combo_name(b, c).c_str(), t.decisions, t.frustum_equal, t.frustum_culled, t.occlusion_equal, t.occluded,
                t.bounds_equal, t.projected, t.outside_plane, t.unprojectable, t.invalid);
            EXPECT_EQ(t.frustum_equal, t.decisions) << combo_name(b, c);
            EXPECT_EQ(t.occlusion_equal, t.decisions) << combo_name(b, c);
            EXPECT_EQ(t.bounds_equal, t.decisions) << combo_name(b, c);
            // The scene exercises every path: culls of both kinds, bounds across the eye plane and
            // outside a clip plane while doing so, invalid inputs.
            EXPECT_GT(t.frustum_culled, t.decisions / 20) << combo_name(b, c);
            EXPECT_GT(t.occluded, t.decisions / 50) << combo_name(b, c);
            EXPECT_GT(t.unprojectable, 0u) << combo_name(b, c);
            EXPECT_GT(t.outside_plane, 0u) << combo_name(b, c);
            EXPECT_GE(t.invalid, 5u * 6u) << combo_name(b, c);
        }
}

/// Counts the patches whose decisions differ between two byte vectors.
std::size_t differences(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    std::size_t d = 0;
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) d += a[i] != b[i];
    return d + (a.size() > b.size() ? a.size() - b.size() : b.size() - a.size());
}

TEST(DisplacedGpu, DifferentInputsGiveDifferentDecisions) {
    // The comparison above has teeth: over the same scene and views, the GPU run on halved ranges,
    // on no ranges, or with another cone or bound disagrees with the CPU on the real input (caf /
    // acon, occlusion), in decisions and in bound values.
    const Scene s = make_scene(11, 1500);
    const PatchBatch batch = test::unchecked_batch(s.patches);
    const std::size_t n = s.patches.size();
    std::vector<DisplacementRange> halved = s.ranges;
    for (DisplacementRange& r : halved) r = {r.d_min * 0.5f, r.d_max * 0.5f};
    DisplacedCuller& g = culler();
    g.set_patches(s.patches, s.ranges);
    std::mt19937 rng(5);
    enum { kSame, kHalved, kNone, kFullCone, kOobb, kCases };
    const char* names[kCases] = {"real input", "halved ranges", "no ranges", "full cone", "oobb"};
    std::size_t decision_diff[kCases] = {}, bound_diff[kCases] = {};
    const DisplacedBoundKind caf = DisplacedBoundKind::caf;
    for (const TestView& tv : make_views(s, 21)) {
        const HiZPyramid hiz = make_hiz(s, tv.view, rng);
        g.set_hiz(hiz);
        std::vector<std::uint8_t> cpu(n);
        std::vector<DisplacedBound> cpu_b(n);
        cull_displaced_occlusion(batch.view(), s.ranges.data(), caf, NormalConeKind::acon, tv.view, hiz, cpu.data());
        compute_displaced_bounds(batch.view(), s.ranges.data(), caf, NormalConeKind::acon, tv.view, cpu_b.data());
        for (int c = 0; c < kCases; ++c) {
            g.set_ranges(c == kHalved ? halved : c == kNone ? std::vector<DisplacementRange>{} : s.ranges);
            std::vector<std::uint8_t> gpu;
            std::vector<DisplacedBound> gpu_b;
            g.cull_occlusion(c == kOobb ? DisplacedBoundKind::oobb : caf,
                             c == kFullCone ? NormalConeKind::full : NormalConeKind::acon, tv.view, &gpu, &gpu_b);
            ASSERT_EQ(gpu.size(), n);
            ASSERT_EQ(gpu_b.size(), n);
            for (std::size_t p = 0; p < n; ++p) {
                decision_diff[c] += cpu[p] != gpu[p];
                bound_diff[c] += !same_bound(cpu_b[p], gpu_b[p]);
            }
        }
    }
    std::printf("[ displaced ] GPU vs CPU caf/acon occlusion, 6 views x %zu patches: differing decisions / bounds:", n);
    for (int c = 0; c < kCases; ++c) std::printf(" %s %zu / %zu;", names[c], decision_diff[c], bound_diff[c]);
    std::printf("\n");
    EXPECT_EQ(decision_diff[kSame], 0u);
    EXPECT_EQ(bound_diff[kSame], 0u);
    for (int c = kHalved; c < kCases; ++c) {
        EXPECT_GT(decision_diff[c], 0u) << names[c];
        EXPECT_GT(bound_diff[c], n) << names[c];
    }
}

TEST(DisplacedGpu, InvalidViewCullsNothing) {
    const Scene s = make_scene(13, 100);
    const std::size_t n = s.patches.size();
    Camera cam;
    Mat4 ortho_like = cam.projection();
    ortho_like.at(3, 2) = 0.0f;  // not of the glFrustum form: make_displaced_cull_view refuses it
    ortho_like.at(3, 3) = 1.0f;
    const DisplacedCullView view = make_displaced_cull_view(cam.view(), ortho_like, ClipDepth::zero_to_one);
    ASSERT_FALSE(view.valid);
    DisplacedCuller& g = culler();
    g.set_patches(s.patches, s.ranges);
    std::vector<std::uint8_t> culled;
    std::vector<DisplacedBound> bounds;
    g.cull_frustum(DisplacedBoundKind::caf, NormalConeKind::acon, view, &culled, &bounds);
    ASSERT_EQ(culled.size(), n);
    ASSERT_EQ(bounds.size(), n);
    for (std::size_t p = 0; p < n; ++p) {
        EXPECT_EQ(culled[p], 0) << p;
        EXPECT_EQ(bounds[p].status, kDisplacedBoundInvalid) << p;
    }
}

TEST(DisplacedGpu, ReadsTheRenderersPatchBuffer) {
    // use_patch_buffer: the renderer's control points (no second upload), ranges set separately.
    const std::vector<BezierPatch> patches = test::split_teapot(1);
    std::mt19937 rng(3);
    std::vector<DisplacementRange> ranges;
    ranges.reserve(patches.size());
    for (const BezierPatch& p : patches) ranges.push_back(random_range(rng, patch_size(p)));
    PatchRenderer renderer(test::context());
    renderer.set_patches(patches);
    DisplacedCuller& g = culler();
    g.use_patch_buffer(renderer.patch_buffer(), patches.size());
    g.set_ranges(ranges);
    const PatchBatch batch = test::unchecked_batch(patches);
    Camera cam;
    cam.eye = {0, 0, 1.2f};  // inside the body, looking along +x: the patches behind the eye are culled
    cam.target = {1, 0, 1.2f};
    cam.z_near = 0.05f;
    cam.up = {0, 0, 1};
    const DisplacedCullView view = make_displaced_cull_view(cam.view(), cam.projection(), ClipDepth::zero_to_one);
    std::vector<std::uint8_t> cpu(patches.size()), gpu;
    cull_displaced_frustum(batch.view(), ranges.data(), DisplacedBoundKind::caf, NormalConeKind::con, view, cpu.data());
    g.cull_frustum(DisplacedBoundKind::caf, NormalConeKind::con, view, &gpu);
    EXPECT_EQ(differences(cpu, gpu), 0u);
    EXPECT_GT(std::count(cpu.begin(), cpu.end(), 1), 0);
    EXPECT_LT(std::count(cpu.begin(), cpu.end(), 1), static_cast<long>(patches.size()));
}

TEST(DisplacedGpu, BatchUploadMatchesTheCpu) {
    // set_patches from a structure-of-arrays batch (the CPU kernels' input) with its ranges pointer.
    const Scene s = make_scene(14, 200);
    const PatchBatch batch = test::unchecked_batch(s.patches);
    const std::size_t n = s.patches.size();
    const std::vector<TestView> views = make_views(s, 41);
    const DisplacedCullView& view = views[2].view;  // free: some patches outside
    DisplacedCuller& g = culler();
    g.set_patches(batch.view(), s.ranges.data());
    ASSERT_EQ(g.patch_count(), n);
    std::vector<std::uint8_t> cpu(n), gpu;
    cull_displaced_frustum(batch.view(), s.ranges.data(), DisplacedBoundKind::caf, NormalConeKind::full, view,
                           cpu.data());
    g.cull_frustum(DisplacedBoundKind::caf, NormalConeKind::full, view, &gpu);
    EXPECT_EQ(differences(cpu, gpu), 0u);
    EXPECT_GT(std::count(cpu.begin(), cpu.end(), 1), 0);
    // Without ranges: the undisplaced bounds (ranges = null on the CPU).
    g.set_patches(batch.view());
    cull_displaced_frustum(batch.view(), nullptr, DisplacedBoundKind::caf, NormalConeKind::full, view, cpu.data());
    g.cull_frustum(DisplacedBoundKind::caf, NormalConeKind::full, view, &gpu);
    EXPECT_EQ(differences(cpu, gpu), 0u);
}

TEST(DisplacedGpu, MisuseThrows) {
    DisplacedCuller fresh(test::context());
    fresh.set_patches(test::split_teapot(0));
    const Camera cam;
    const DisplacedCullView view = make_displaced_cull_view(cam.view(), cam.projection(), ClipDepth::zero_to_one);
    EXPECT_THROW(fresh.cull_occlusion(DisplacedBoundKind::caf, NormalConeKind::full, view), Error);  // no Hi-Z
    EXPECT_THROW(fresh.set_ranges(std::vector<DisplacementRange>(3)), Error);
    EXPECT_THROW(fresh.set_patches(test::split_teapot(0), std::vector<DisplacementRange>(5)), Error);
    EXPECT_THROW(fresh.use_patch_buffer(0xFFFFFFu, 1), Error);
}

}  // namespace
}  // namespace patchcull::gl
