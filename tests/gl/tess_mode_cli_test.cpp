// `render --tess-mode uniform|adaptive [--tess-distance D]` (tools/render_options.h, TessOptions;
// the adaptive tessellation by distance of Niessner & Loop, "Patch-Based Occlusion Culling for Hardware
// Tessellation" §6.3): `--verify` finds no false culls under
// adaptive tessellation on the default scene, the JSON names the mode, adaptive tessellation
// draws a different surface sampling than uniform at the same maximum, and bad values are
// one-line errors with exit status 2. In the gl suite because it needs OpenGL; the default scene
// at 96x54, level 4, three frames.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

const std::string kSmallDefault = "render default --size 96x54 --tess 4 --frames 3 ";

}  // namespace

TEST(TessModeCli, AdaptiveVerifiesWithoutFalseCullsOnTheDefaultScene) {
    const CliRun r = run(kSmallDefault + "--tess-mode adaptive --cull all --verify --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["tess_mode"], "adaptive");
    EXPECT_EQ(j["tess"], 4);
    EXPECT_EQ(j["verified"], true);
    EXPECT_EQ(j["false_culls"], 0);
    ASSERT_EQ(j["frames"].size(), 3u);
    for (const auto& frame : j["frames"]) {
        EXPECT_EQ(frame["false_culls"], 0) << frame.dump();
        // The scene's walls and characters hide patches: the comparison above is not vacuous.
        EXPECT_GT(frame["occlusion_culled"].get<std::size_t>() + frame["frustum_culled"].get<std::size_t>(), 0u)
            << frame.dump();
    }
}

TEST(TessModeCli, ModeIsInTheJsonAndAdaptiveChangesTheImage) {
    const std::string uniform_png = scratch_dir() + "/tess_uniform.png";
    const std::string adaptive_png = scratch_dir() + "/tess_adaptive.png";
    const std::string near_png = scratch_dir() + "/tess_near.png";
    const CliRun uniform = run(kSmallDefault + "--cull none --out " + uniform_png + " --json");
    ASSERT_EQ(uniform.status, 0) << uniform.err;
    EXPECT_EQ(nlohmann::json::parse(uniform.out)["tess_mode"], "uniform");
    // A reference distance far beyond the scene: every edge gets the full level, as uniform.
    const CliRun far =
        run(kSmallDefault + "--cull none --tess-mode adaptive --tess-distance 1000 --out " + adaptive_png + " --json");
    ASSERT_EQ(far.status, 0) << far.err;
    EXPECT_EQ(nlohmann::json::parse(far.out)["tess_mode"], "adaptive");
    EXPECT_EQ(slurp(adaptive_png), slurp(uniform_png)) << "adaptive at a huge reference distance must be uniform";
    // A tiny reference distance: every edge gets level 1, a visibly coarser surface.
    const CliRun near =
        run(kSmallDefault + "--cull none --tess-mode adaptive --tess-distance 0.01 --out " + near_png + " --json");
    ASSERT_EQ(near.status, 0) << near.err;
    EXPECT_NE(slurp(near_png), slurp(uniform_png)) << "--tess-distance had no effect";
}

TEST(TessModeCli, BadValuesAreOneLineErrors) {
    for (const char* command : {"render default --frames 1 --size 8x8 ", "view default --frames 1 --size 8x8 "}) {
        const std::string c = command;
        expect_one_line_error(run(c + "--tess-mode distance"), "--tess-mode");
        expect_one_line_error(run(c + "--tess-mode ''"), "--tess-mode");
        expect_one_line_error(run(c + "--tess-mode adaptive --tess-distance 0"), "--tess-distance");
        expect_one_line_error(run(c + "--tess-mode adaptive --tess-distance=-1"), "--tess-distance");
        expect_one_line_error(run(c + "--tess-mode adaptive --tess-distance nan"), "--tess-distance");
        expect_one_line_error(run(c + "--tess-mode adaptive --tess-distance 1e-50"), "--tess-distance");
        expect_one_line_error(run(c + "--tess-mode adaptive --tess-distance 2e9"), "--tess-distance");
        expect_one_line_error(run(c + "--tess-mode adaptive --tess-distance far"), "--tess-distance");
        // A reference distance means nothing to uniform tessellation.
        expect_one_line_error(run(c + "--tess-distance 2"), "--tess-distance");
        expect_one_line_error(run(c + "--tess-mode uniform --tess-distance 2"), "--tess-distance");
    }
}
