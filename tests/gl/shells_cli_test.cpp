// `render --verify` on meshes of several shells (README: "What contributes a pixel"): two equal
// spheres, one written inside out, must be drawn and back-patch culled exactly like the same
// pair written outward, with no false culls, under both schemes. Verification alone cannot see
// a shell left inside out (the reference and the culled frame share the orientation), so the
// counts are compared with the outward pair's: the whole-mesh rule called the pair flat (no
// back-patch culling at all) and drew it two-sided. The same for two tori.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

std::string shells_file(const char* name) { return std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/shells/" + name; }

}  // namespace

TEST(ShellsCli, ReversedShellIsCulledLikeItsOutwardTwin) {
    struct Case {
        const char* scheme;
        const char* backpatch;
    };
    for (const Case c : {Case{"acc", "tcone"}, Case{"osd", "ptp"}}) {
        SCOPED_TRACE(std::string(c.scheme) + " " + c.backpatch);
        const std::string args = std::string(" --scheme ") + c.scheme + " --cull all --backpatch " + c.backpatch +
                                 " --size 96x64 --tess 2 --frames 2 --verify --json";
        const CliRun plain = run("render " + shells_file("two_spheres.obj") + args);
        const CliRun reversed = run("render " + shells_file("two_spheres_one_reversed.obj") + args);
        ASSERT_EQ(plain.status, 0) << plain.err;
        ASSERT_EQ(reversed.status, 0) << reversed.err;
        EXPECT_NE(reversed.err.find("1 of 2 closed shells oriented inward"), std::string::npos) << reversed.err;
        const auto p = nlohmann::json::parse(plain.out), r = nlohmann::json::parse(reversed.out);
        EXPECT_EQ(r["backpatch"], c.backpatch);  // a solid: one-sided, back-patch culled
        EXPECT_EQ(r["verified"], true);
        EXPECT_EQ(r["false_culls"], 0);
        EXPECT_EQ(p["false_culls"], 0);
        std::size_t culled = 0;
        for (int f = 0; f < 2; ++f) {
            for (const char* key : {"backpatch_culled", "visible", "pass1_drawn"})
                EXPECT_EQ(r["frames"][f][key], p["frames"][f][key]) << key << " frame " << f;
            culled += r["frames"][f]["backpatch_culled"].get<std::size_t>();
        }
        EXPECT_GT(culled, 0u);
    }
}

TEST(ShellsCli, TwoToriOneReversedAreASolid) {
    const CliRun r = run("render " + shells_file("two_tori_one_reversed.obj") +
                         " --cull all --size 96x64 --tess 2 --frames 2 --verify --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["backpatch"], "tcone");  // not two-sided
    EXPECT_EQ(j["false_culls"], 0);
    EXPECT_GT(j["frames"][1]["backpatch_culled"].get<std::size_t>(), 0u);
}
