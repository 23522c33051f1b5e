// OpenSubdiv's own regression shapes (tests/data/opensubdiv, tags read by patchcull/import/obj.h) through
// the GPU pipeline: `render --verify` finds no false cull with either scheme, a shape with a hole
// is drawn two-sided (no back-patch culling), and a closed one is back-patch culled.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

std::string shape(const char* name) {
    return std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/opensubdiv/" + name + ".obj";
}

}  // namespace

TEST(GpuOpenSubdivShapes, VerifyFindsNoFalseCullsWithEitherScheme) {
    struct Case {
        const char* name;
        const char* backpatch;  // what the pipeline reports: "off" for a surface that is not closed
    };
    // The helmet is open; the cube has a face tagged as a hole (closed control mesh, open surface);
    // the infinitely sharp cubes are closed solids.
    const Case cases[] = {{"catmark_helmet", "off"}, {"catmark_hole_test1", "off"}, {"catmark_cubes_infsharp", "ptp"}};
    for (const Case& c : cases)
        for (const char* scheme : {"acc", "osd"}) {
            SCOPED_TRACE(std::string(c.name) + " " + scheme);
            const CliRun r = run("render " + shape(c.name) + " --scheme " + scheme +
                                 " --size 96x64 --tess 2 --frames 4 --cull all --backpatch ptp --verify --json");
            ASSERT_EQ(r.status, 0) << r.err;
            const auto j = nlohmann::json::parse(r.out);
            EXPECT_EQ(j["verified"], true);
            EXPECT_EQ(j["false_culls"], 0);
            EXPECT_EQ(j["backpatch"], c.backpatch);
            for (const auto& frame : j["frames"]) {
                EXPECT_EQ(frame["false_culls"], 0) << "frame " << frame["frame"];
                EXPECT_GT(frame["visible"].get<int>(), 0) << "frame " << frame["frame"];
            }
        }
    // The closed cubes are back-patch culled (by osd, whose many small patches face away whole).
    const CliRun r = run("render " + shape("catmark_cubes_infsharp") +
                         " --scheme osd --size 96x64 --tess 2 --frames 4 --cull all --backpatch ptp --verify --json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_GT(nlohmann::json::parse(r.out)["frames"][3]["backpatch_culled"].get<int>(), 0);
}
