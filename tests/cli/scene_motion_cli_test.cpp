// Scene motion checked before rendering (check_scene_motion, patchcull/scene_file.h): `render`
// of a scene whose object the time offset and velocity carry beyond the scene coordinate limit
// is refused with one line naming the file, the JSON path and the frame, exit status 2, and
// nothing rendered (no GL context is made: the check runs first). And the objects of one model
// in two schemes keep their unique default names through `render --cull auto`'s JSON.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

std::string test_scene(const char* name) { return std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/scenes/" + name; }

}  // namespace

TEST(SceneMotionCli, MotionBeyondTheLimitIsRefusedBeforeRendering) {
    // 1e6 units per second for a time offset of 1000 s: 1e9 units out at frame 0.
    const CliRun r = run("render " + test_scene("runaway.json") + " --frames 3 --size 64x48 --tess 1 --verify --json");
    expect_one_line_error(r, "runaway.json: objects[1].animation.time_offset: the moving model ('monsterfrog#0') reaches x = ");
    EXPECT_NE(r.err.find(" at frame 0 (time 0 s); scenes take world coordinates up to "), std::string::npos) << r.err;
    // The same refusal from the other commands that render a scene's frames.
    const CliRun demo = run("demo --scene " + test_scene("runaway.json") + " --frames 2 --size 64x48");
    expect_one_line_error(demo, "runaway.json: objects[1].animation.time_offset: ");
}

TEST(SceneMotionCli, DefaultNamesOfOneModelInTwoSchemesStayApart) {
    const std::string scene = write_file("two_schemes.json", R"({"objects": [
        {"model": "bigguy", "transform": {"height": 1}},
        {"model": "bigguy", "scheme": "osd", "transform": {"position": [1.2, 0, 0], "height": 1}}],
      "camera": {"orbit": {"target": [0.6, 0.5, 0], "distance": 3, "height": 0.5}}})");
    const CliRun r = run("render " + scene + " --cull auto --frames 1 --size 32x24 --tess 1 --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json objects = nlohmann::json::parse(r.out)["frames"][0]["auto_objects"];
    ASSERT_EQ(objects.size(), 2u) << objects.dump();
    EXPECT_EQ(objects[0]["name"], "bigguy:acc#0");
    EXPECT_EQ(objects[1]["name"], "bigguy:osd#0");
}
