// `patchcull render MODEL --scheme osd --patch-source osd-table` (tools/render_osd_table.h): the
// model's OpenSubdiv patch table drawn with OpenSubdiv's own GLSL patch shaders and culled in
// place; --verify finds no false cull and every culled frame's id buffer equals the unculled one;
// the JSON names the patch source (bezier by default); bad values and flags that do not apply are
// one-line errors naming the flag (exit 2).
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

TEST(OsdTableCli, RenderVerifiesTheOsdTableAndCulls) {
    const CliRun r = run("render " + model("bigguy.obj") +
                         " --scheme osd --patch-source osd-table --frames 3 --size 96x72 --tess 4 --verify --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["patch_source"], "osd-table");
    EXPECT_EQ(j["cull"], "all");
    EXPECT_EQ(j["backpatch"], "tcone");  // BigGuy is closed
    EXPECT_EQ(j["verified"], true);
    EXPECT_EQ(j["false_culls"], 0);
    ASSERT_EQ(j["frames"].size(), 3u);
    std::size_t back = 0, occluded = 0;
    for (const auto& f : j["frames"]) {
        EXPECT_EQ(f["differing_pixels"], 0) << f.dump();
        back += f["backpatch_culled"].get<std::size_t>();
        occluded += f["occlusion_culled"].get<std::size_t>();
    }
    EXPECT_GT(back, 0u) << r.out;
    EXPECT_GT(occluded, 0u) << r.out;
}

TEST(OsdTableCli, JsonNamesThePatchSourceAndBadValuesAreOneLineErrors) {
    const CliRun r = run("render teapot --frames 1 --size 16x16 --tess 1 --json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["patch_source"], "bezier");
    const std::string bigguy = "render " + model("bigguy.obj") + " --frames 1 --size 16x16 ";
    expect_one_line_error(run(bigguy + "--patch-source sideways --json"), "--patch-source");
    expect_one_line_error(run(bigguy + "--patch-source osd-table --json"),
                          "--patch-source osd-table: needs --scheme osd");
    expect_one_line_error(run(bigguy + "--scheme osd --patch-source osd-table --aggressive --json"), "--aggressive");
    expect_one_line_error(run(bigguy + "--scheme osd --patch-source osd-table --cull auto --json"), "--cull auto");
    expect_one_line_error(run(bigguy + "--scheme osd --patch-source osd-table --tess 17 --json"), "--tess");
    expect_one_line_error(run("render teapot --scheme osd --patch-source osd-table --json"), "teapot");
}
