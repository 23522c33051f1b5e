// Scene motion checked before rendering (check_scene_motion, patchcull/import/scene_file.h): `render`
// of a scene whose object the time offset and velocity carry beyond the scene coordinate limit
// is refused with one line naming the file, the JSON path and the frame, exit status 2, and
// nothing rendered (no GL context is made: the check runs first). (The default names of one model
// in two schemes, which needs a render, are tested in tests/gl/scene_names_cli_test.cpp.)
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
    expect_one_line_error(
        r, "runaway.json: objects[1].animation.time_offset: the moving model ('monsterfrog#0') reaches x = ");
    EXPECT_NE(r.err.find(" at frame 0 (time 0 s); scenes take world coordinates up to "), std::string::npos) << r.err;
    // The same refusal from the other commands that render a scene's frames.
    const CliRun demo = run("demo --scene " + test_scene("runaway.json") + " --frames 2 --size 64x48");
    expect_one_line_error(demo, "runaway.json: objects[1].animation.time_offset: ");
}
