// Models far from the origin: engines place objects at world
// coordinates of 1e4 - 1e7 units. Before the OBJ reader re-centred positions in double
// (ControlMesh::origin), BigGuy translated by 1e5 had CPU frustum false culls (5 and 25 in 200
// free views) and ptp culled nothing (its rounding margin grows with |position|); at 1e7 float
// positions themselves were off by up to half a unit. Each test here fails on that code.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "cli/cli_test_util.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/frustum.h"
#include "patchcull/eval/cull_eval.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/import/obj.h"

using namespace patchcull;

namespace {

std::map<std::string, CullMethodResult> cull(const PatchFrame& frame, ViewMode mode, int views) {
    CullEvalOptions options;
    options.views = views;
    options.seed = 7;
    options.mode = mode;
    options.methods = cull_method_names();
    std::map<std::string, CullMethodResult> by_name;
    for (const CullMethodResult& r : evaluate_cull(frame, nullptr, options).methods) by_name[r.name] = r;
    return by_name;
}

}  // namespace

TEST(FarOrigin, ObjReaderRecentresInDouble) {
    // A unit quad at 1e7 + 0.25: as floats (spacing 1 there) its corners would collapse.
    std::istringstream in(
        "v 10000000.25 20000000.5 -30000000.125\n"
        "v 10000001.25 20000000.5 -30000000.125\n"
        "v 10000001.25 20000001.5 -30000000.125\n"
        "v 10000000.25 20000001.5 -30000000.125\n"
        "f 1 2 3 4\n");
    const ControlMesh m = parse_obj(in, "far.obj");
    EXPECT_EQ(m.origin.x, 10000000.75);
    EXPECT_EQ(m.origin.y, 20000001.0);
    EXPECT_EQ(m.origin.z, -30000000.125);
    ASSERT_EQ(m.positions.size(), 4u);
    const Vec3 expected[4] = {{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}};
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(m.positions[i].x, expected[i].x) << i;
        EXPECT_EQ(m.positions[i].y, expected[i].y) << i;
        EXPECT_EQ(m.positions[i].z, expected[i].z) << i;
    }
}

TEST(FarOrigin, MeshNearTheOriginKeepsOriginZeroAndItsPositions) {
    // The rule: re-centre when the box centre is farther from 0 (largest |component|) than the
    // box's diagonal. First quad: centre x = 1.5 > diagonal 1.41, it moves; the second, centre
    // (0.5, 0.5, 0.05), keeps origin 0 and its parsed floats.
    std::istringstream far_in("v 1 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nf 1 2 3 4\n");
    const ControlMesh moved = parse_obj(far_in, "a.obj");
    EXPECT_EQ(moved.origin.x, 1.5);
    EXPECT_EQ(moved.positions[0].x, -0.5f);
    std::istringstream near_in("v 0 0 0\nv 1 0 0\nv 1 1 0.1\nv 0 1 0\nf 1 2 3 4\n");
    const ControlMesh kept = parse_obj(near_in, "b.obj");
    EXPECT_EQ(kept.origin.x, 0.0);
    EXPECT_EQ(kept.origin.y, 0.0);
    EXPECT_EQ(kept.origin.z, 0.0);
    EXPECT_EQ(kept.positions[2].z, 0.1f);
}

// Every method (frustum, frustum-disp, tcone, ncone, ptp, ptp-pcnt), both view modes, both
// schemes: no false cull and the untranslated model's cull rate (within 1 point) at 1e5 and 1e7.
TEST(FarOrigin, TranslatedBigGuyCullsAsAtTheOrigin) {
    for (Scheme scheme : {Scheme::acc, Scheme::osd}) {
        const LoadedModel base = load_model(shipped_model_path("bigguy.obj"), scheme, 0);
        EXPECT_EQ(base.origin.x, 0.0);  // BigGuy itself is centred near 0: unchanged
        for (ViewMode mode : {ViewMode::free, ViewMode::contain}) {
            const int views = mode == ViewMode::free ? 24 : 8;
            const auto reference = cull(base.rest, mode, views);
            for (double t : {1e5, 1e7}) {
                const std::string path = patchcull::cli_test::write_file(
                    "bigguy_" + std::to_string(int(std::log10(t))) + ".obj", patchcull::cli_test::translated_bigguy(t));
                const LoadedModel far = load_model(path, scheme, 0);
                EXPECT_NEAR(far.origin.x, t, 10.0);
                const auto r = cull(far.rest, mode, views);
                for (const auto& [name, ref] : reference) {
                    const std::string what = std::string(scheme_name(scheme)) + " " + view_mode_name(mode) +
                                             " t=" + std::to_string(t) + " " + name;
                    EXPECT_EQ(r.at(name).false_culls, 0u) << what;
                    EXPECT_NEAR(r.at(name).cull_rate, ref.cull_rate, 0.01) << what;
                }
            }
        }
    }
}

// A world camera at 1e7 moved into the local frame in double sees the local patches exactly as
// the same camera at the origin does: the same frustum decisions on BigGuy, view by view.
TEST(FarOrigin, WorldCameraLocalMatchesTheCameraAtTheOrigin) {
    const LoadedModel m = load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0);
    const PatchBatch batch = make_batch(m.rest.patches);
    const DVec3 origin{1e7 + 0.3, -2e7, 5e6};
    ViewGenerator views(patch_bounds(m.rest), ViewMode::free, 3);
    std::size_t culled_somewhere = 0;
    for (int v = 0; v < 50; ++v) {
        const Camera cam = views.next();
        const Camera back = to_world(cam, origin).local(origin);
        std::vector<std::uint8_t> a(batch.size()), b(batch.size());
        cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(cam.view_projection(), ClipDepth::zero_to_one),
                            a.data());
        cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(back.view_projection(), ClipDepth::zero_to_one),
                            b.data());
        std::size_t differ = 0;
        for (std::size_t i = 0; i < a.size(); ++i) differ += a[i] != b[i];
        // Eye and target come back to float rounding of numbers of BigGuy's size (an ulp or two).
        EXPECT_LE(differ, 2u) << "view " << v;
        for (std::uint8_t c : b) culled_somewhere += c;
    }
    EXPECT_GT(culled_somewhere, 1000u);  // not vacuous: free views cull
}

// WorldCamera::local keeps the view direction of a target one unit from an eye 1e7 from origin
// (rounding both points to float would leave a direction error of order 1).
TEST(FarOrigin, WorldCameraLocalKeepsTheViewDirection) {
    WorldCamera w;
    w.eye = {1e7 + 0.3, 0.7, 0};
    w.target = {1e7 + 0.3 + 0.6, 0.7 + 0.8, 0};
    const Camera c = w.local({0, 0, 0});
    const Vec3 d = normalize(c.target - c.eye);
    EXPECT_NEAR(d.x, 0.6f, 1e-6f);
    EXPECT_NEAR(d.y, 0.8f, 1e-6f);
    EXPECT_NEAR(d.z, 0.0f, 1e-6f);
}
