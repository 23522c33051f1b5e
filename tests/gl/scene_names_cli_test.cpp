// The objects of one model in two schemes keep their unique default names (scheme in the key)
// through `render --cull auto`'s JSON. In the gl suite: it renders (the GL driver's allocations
// are reported by LeakSanitizer in the sanitizer build, which runs the cli suite).
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

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
