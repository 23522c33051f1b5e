// The "distance" view distribution of evaluate_cull (patchcull/eval/cull_eval.h, DistanceViews):
// its contract at the library level, below the CLI's flag parsing (tests/cli/cli_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "patchcull/core/error.h"
#include "patchcull/eval/cull_eval.h"
#include "patchcull/import/model_loader.h"

using namespace patchcull;

namespace {

CullEvalResult run(const PatchFrame& frame, DistanceViews range, std::uint64_t seed, int views = 40) {
    CullEvalOptions o;
    o.views = views;
    o.seed = seed;
    o.distance = range;
    o.methods = {"frustum", "frustum-disp", "ptp"};
    return evaluate_cull(frame, nullptr, o);
}

}  // namespace

TEST(DistanceViews, RangesOutsideTheContractThrowNamingTheBound) {
    const LoadedModel m = load_model("teapot", Scheme::acc, 0);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (DistanceViews bad : {DistanceViews{0.99f, 2.0f}, DistanceViews{2.0f, 1.5f}, DistanceViews{nan, 2.0f},
                              DistanceViews{1.0f, nan}, DistanceViews{1.0f, 1001.0f}}) {
        try {
            run(m.rest, bad, 1, 1);
            ADD_FAILURE() << "accepted " << bad.min << ".." << bad.max;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("distance range"), std::string::npos) << e.what();
        }
    }
}

TEST(DistanceViews, WholeObjectInViewAtTheRequestedDistanceAndSeeded) {
    const LoadedModel m = load_model("teapot", Scheme::acc, 0);
    // One fixed multiple: every eye is m / sin(22.5 deg) radii from the centre of the (padded)
    // bounding box's sphere, and the sphere touches the sides, so nothing is outside the view.
    for (float multiple : {1.0f, 2.0f, 7.5f}) {
        const CullEvalResult r = run(m.rest, DistanceViews{multiple, multiple}, 3);
        EXPECT_NEAR(r.mean_eye_distance_radii, multiple / std::sin(22.5 * 3.14159265358979 / 180), 1e-3 * multiple);
        EXPECT_EQ(r.methods[0].culled, 0u) << multiple;  // frustum
        EXPECT_EQ(r.methods[1].culled, 0u) << multiple;  // frustum-disp
        for (const CullMethodResult& method : r.methods) EXPECT_EQ(method.false_culls, 0u) << method.name;
    }
    // The seed decides the views: the same seed repeats every count, another changes ptp's.
    const CullEvalResult a = run(m.rest, DistanceViews{}, 5), b = run(m.rest, DistanceViews{}, 5),
                         c = run(m.rest, DistanceViews{}, 6);
    EXPECT_EQ(a.methods[2].culled, b.methods[2].culled);
    EXPECT_EQ(a.mean_eye_distance_radii, b.mean_eye_distance_radii);
    EXPECT_NE(a.mean_eye_distance_radii, c.mean_eye_distance_radii);
}
