// Property tests of the back-patch kernels (Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for
// Hardware Tessellation") on real models against both ground truths: no culled patch may have
// e . T(u,v) > 0 at a dense sample, and no triangle of its
// level-16 tessellation may face the eye. Views: whole-object views, free views (eyes inside
// the model), and eyes very close to the surface. The last test shows the truth catches a
// kernel that is not conservative.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/core/parallel.h"
#include "patchcull/eval/cull_eval.h"
#include "patchcull/import/model_loader.h"

using namespace patchcull;

namespace {

const std::vector<std::string> kMethods = {"tcone", "ncone", "ptp", "ptp-pcnt"};

CullEvalResult run_methods(const PatchFrame& frame, ViewMode mode, int views, std::uint64_t seed) {
    CullEvalOptions options;
    options.views = views;
    options.seed = seed;
    options.mode = mode;
    options.methods = kMethods;
    return evaluate_cull(frame, nullptr, options);
}

void expect_no_false_culls(const CullEvalResult& r, const char* what) {
    for (const CullMethodResult& m : r.methods) EXPECT_EQ(m.false_culls, 0u) << m.name << " " << what;
}

// Level-16 tessellation triangles of every culled patch, for eyes the caller chooses.
//
// Finding (docs/RESULTS.md, "secant triangles"): Loop, Niessner & Eisenacher's criterion is the continuous surface,
// e . T(u,v) <= 0. A secant triangle of a back-facing curved patch near the silhouette can face
// an eye that is close to the surface even though every tangent plane faces away (seen: eye
// 0.2-0.5 units from a 31.7-unit model, behind all sampled tangent planes by 0.03-0.07 units).
// tcone and ncone, whose cones carry margins, never showed it; ptp, the tightest test, does in
// ~5e-5 of its culls. This test therefore demands: no triangle violation at all for the cones;
// for ptp, every triangle violation must be such a secant case (all surface samples strictly
// back-facing, i.e. the decision is right for the surface) and they must stay rare.
struct TriangleReport {
    std::uint64_t culled = 0, violations = 0;
};

void check_tessellation_triangles(const PatchFrame& frame, const std::vector<Camera>& cameras,
                                  TriangleReport reports[4]) {
    const PatchBatch batch = make_batch(frame.patches);
    const std::size_t n = frame.patches.size();
    std::vector<PointD> grid(n * 17 * 17);
    std::vector<PlaneD> planes(n * 17 * 17);
    for (std::size_t p = 0; p < n; ++p) {
        sample_patch_points(frame.patches[p], 17, &grid[p * 289]);
        sample_tangent_planes(frame.patches[p], 17, &planes[p * 289]);
    }
    std::vector<std::uint8_t> culled(n);
    for (const Camera& c : cameras) {
        const Mat4 clip = c.view_projection();
        const float alpha = clip_space_eye_alpha(c.projection());
        for (int method = 0; method < 4; ++method) {
            if (method == 0) cull_tcone_simd(batch.view(), c.eye, culled.data());
            if (method == 1) cull_ncone_simd(batch.view(), c.eye, culled.data());
            if (method == 2) cull_ptp_simd(batch.view(), clip, alpha, PtpRule::ncnt, culled.data());
            if (method == 3) cull_ptp_simd(batch.view(), clip, alpha, PtpRule::pcnt, culled.data());
            for (std::size_t p = 0; p < n; ++p) {
                if (!culled[p]) continue;
                ++reports[method].culled;
                if (!any_tessellation_triangle_faces_eye(&grid[p * 289], 17, c.eye)) continue;
                ++reports[method].violations;
                ASSERT_GE(method, 2) << kMethods[method] << " patch " << p
                                     << ": a cone method must have no facing triangle";
                ASSERT_FALSE(any_plane_faces_eye(&planes[p * 289], 289, c.eye)) << kMethods[method] << " patch " << p;
            }
        }
    }
}

void expect_no_facing_triangles(const PatchFrame& frame, const std::vector<Camera>& cameras) {
    TriangleReport reports[4];
    check_tessellation_triangles(frame, cameras, reports);
    for (int method = 0; method < 4; ++method) {
        EXPECT_LE(reports[method].violations * 2000, reports[method].culled + 2000)
            << kMethods[method] << ": " << reports[method].violations << " of " << reports[method].culled;
        if (reports[method].violations)
            std::printf("[ secant ] %s: %llu of %llu culled patches have a level-16 triangle facing the eye\n",
                        kMethods[method].c_str(), static_cast<unsigned long long>(reports[method].violations),
                        static_cast<unsigned long long>(reports[method].culled));
    }
}

// Eyes within 0.1%-2% of the model's size of a random surface point, on the front side.
std::vector<Camera> close_eyes(const PatchFrame& frame, int count, std::uint32_t seed) {
    std::mt19937 rng(seed);
    const Bounds b = patch_bounds(frame);
    const float size = length(b.max - b.min);
    std::uniform_int_distribution<std::size_t> patch(0, frame.patches.size() - 1);
    std::uniform_real_distribution<float> unit(0, 1);
    std::vector<Camera> cams;
    while (static_cast<int>(cams.size()) < count) {
        const SurfacePoint s = evaluate_surface(frame.patches[patch(rng)], unit(rng), unit(rng));
        if (length(s.normal) == 0) continue;
        Camera c;
        c.eye = s.position + normalize(s.normal) * (size * (0.001f + 0.02f * unit(rng)));
        c.target = s.position;
        c.z_near = size * 1e-4f;
        c.z_far = size * 4;
        cams.push_back(c);
    }
    return cams;
}

}  // namespace

TEST(BackpatchProperty, BigGuyAccWholeObjectFreeAndCloseViews) {
    const LoadedModel m = load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0);
    const CullEvalResult contain = run_methods(m.rest, ViewMode::contain, 400, 1);
    expect_no_false_culls(contain, "contain");
    expect_no_false_culls(run_methods(m.rest, ViewMode::free, 400, 2), "free");
    // Not vacuous, and in Loop, Niessner & Eisenacher's order on a real model: ptp >= ncone >= tcone > 0.
    EXPECT_GT(contain.methods[0].cull_rate, 0.15);
    EXPECT_GE(contain.methods[1].cull_rate, contain.methods[0].cull_rate);
    EXPECT_GE(contain.methods[2].cull_rate, contain.methods[1].cull_rate);
    expect_no_facing_triangles(m.rest, close_eyes(m.rest, 60, 3));
    ViewGenerator views(patch_bounds(m.rest), ViewMode::contain, 4);
    std::vector<Camera> cams;
    cams.reserve(20);
    for (int i = 0; i < 20; ++i) cams.push_back(views.next());
    expect_no_facing_triangles(m.rest, cams);
}

TEST(BackpatchProperty, MonsterFrogSplitOnceAndOsd) {
    const LoadedModel frog = load_model(shipped_model_path("monsterfrog.obj"), Scheme::acc, 1);
    ASSERT_EQ(frog.rest.patches.size(), 5168u);
    expect_no_false_culls(run_methods(frog.rest, ViewMode::contain, 200, 5), "frog contain");
    expect_no_facing_triangles(frog.rest, close_eyes(frog.rest, 20, 6));
    const LoadedModel osd = load_model(shipped_model_path("bigguy.obj"), Scheme::osd, 0);
    expect_no_false_culls(run_methods(osd.rest, ViewMode::free, 200, 7), "bigguy osd free");
}

TEST(BackpatchProperty, TeapotDegeneratePatches) {
    for (int split : {0, 1}) {
        const LoadedModel m = load_model("teapot", Scheme::acc, split);
        expect_no_false_culls(run_methods(m.rest, ViewMode::contain, 2000, 8 + split), "teapot contain");
        expect_no_false_culls(run_methods(m.rest, ViewMode::free, 2000, 10 + split), "teapot free");
        expect_no_facing_triangles(m.rest, close_eyes(m.rest, 300, 12 + split));
    }
}

// A plausible but wrong kernel: decide by the normal at the patch centre alone. The ground
// truth used above must report its false culls.
TEST(BackpatchProperty, GroundTruthCatchesACentreNormalKernel) {
    const LoadedModel m = load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0);
    const std::size_t n = m.rest.patches.size();
    std::vector<PlaneD> planes(n * 289);
    for (std::size_t p = 0; p < n; ++p) sample_tangent_planes(m.rest.patches[p], 17, &planes[p * 289]);
    ViewGenerator views(patch_bounds(m.rest), ViewMode::contain, 13);
    std::uint64_t false_culls = 0;
    for (int v = 0; v < 100; ++v) {
        const Vec3 eye = views.next().eye;
        for (std::size_t p = 0; p < n; ++p) {
            const SurfacePoint s = evaluate_surface(m.rest.patches[p], 0.5f, 0.5f);
            const bool culled = dot(s.normal, eye - s.position) < 0;
            if (culled && any_plane_faces_eye(&planes[p * 289], 289, eye)) ++false_culls;
        }
    }
    EXPECT_GT(false_culls, 100u);
}

// Regression (docs/RESULTS.md, Finding 1): before the kernels carried a rounding-error margin
// (ptp_schedule.h), ptp culled this nearly edge-on silhouette patch seen from far away: a corner
// tangent plane facing the eye by ~1.5e-5 rad (eye 0.0026 units in front of it, 171 units away)
// computed as back-facing. `patchcull cull monsterfrog.obj --split 1 --methods ptp --views 10000
// --view-mode contain` reported 26 such false culls in ~22 M culls; with the margin it reports 0.
TEST(BackpatchProperty, PtpFloatRoundingFalseCullOnDistantSilhouette) {
    const LoadedModel m = load_model(shipped_model_path("monsterfrog.obj"), Scheme::acc, 1);
    ViewGenerator views(patch_bounds(m.rest), ViewMode::contain, 1);
    Camera camera;
    for (int v = 0; v <= 915; ++v) camera = views.next();
    const PatchBatch batch = make_batch(m.rest.patches);
    std::vector<std::uint8_t> culled(m.rest.patches.size());
    cull_ptp_simd(batch.view(), camera.view_projection(), clip_space_eye_alpha(camera.projection()), PtpRule::ncnt,
                  culled.data());
    std::vector<PlaneD> planes(289);
    sample_tangent_planes(m.rest.patches[1316], 17, planes.data());
    const bool faces = any_plane_faces_eye(planes.data(), 289, camera.eye);
    ASSERT_TRUE(faces) << "the reproducer's patch no longer faces the eye: the test would check nothing";
    EXPECT_FALSE(culled[1316]) << "patch 1316 culled although a tangent plane faces the eye";
}
