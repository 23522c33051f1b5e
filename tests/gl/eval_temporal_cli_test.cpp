// `patchcull eval temporal` (tools/eval/eval_temporal.cpp; Fig. 9 right of Niessner & Loop,
// "Patch-Based Occlusion Culling for Hardware Tessellation"): the JSON contract, no false culls
// against the unculled render of every frame, fractions in [0, 1], and bad flags as one-line
// errors with exit status 2. In the gl suite because it needs OpenGL; BigGuy at 96x96, level 2,
// a few frames (well under a second on llvmpipe).
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

TEST(EvalTemporalCli, JsonHasTheContractShapeAndNoFalseCulls) {
    const CliRun r =
        run("eval temporal " + model("bigguy.obj") + " --speeds 0,10,90 --frames 4 --size 96x96 --tess 2 --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    for (const char* key : {"model", "scheme", "patches", "size", "tess", "frames", "speeds", "false_culls"})
        ASSERT_TRUE(j.contains(key)) << key << " in " << j.dump();
    EXPECT_EQ(j.size(), 8u) << j.dump();
    EXPECT_EQ(j["model"], model("bigguy.obj"));
    EXPECT_EQ(j["scheme"], "acc");
    EXPECT_EQ(j["patches"], 1450);
    EXPECT_EQ(j["size"], nlohmann::json::array({96, 96}));
    EXPECT_EQ(j["tess"], 2);
    EXPECT_EQ(j["frames"], 4);
    EXPECT_EQ(j["false_culls"], 0);
    ASSERT_EQ(j["speeds"].size(), 3u);
    const double expected_speeds[] = {0, 10, 90};
    for (std::size_t i = 0; i < 3; ++i) {
        const auto& row = j["speeds"][i];
        EXPECT_EQ(row.size(), 5u) << row.dump();
        EXPECT_EQ(row["degrees_per_frame"].get<double>(), expected_speeds[i]) << row.dump();
        for (const char* key : {"occluded_fraction", "converged_occluded_fraction", "frustum_fraction"}) {
            ASSERT_TRUE(row.contains(key) && row[key].is_number()) << key << " in " << row.dump();
            EXPECT_GE(row[key].get<double>(), 0.0) << key << " in " << row.dump();
            EXPECT_LE(row[key].get<double>(), 1.0) << key << " in " << row.dump();
        }
        ASSERT_TRUE(row["false_culls"].is_number_unsigned()) << row.dump();
        EXPECT_EQ(row["false_culls"], 0) << row.dump();
        // BigGuy seen whole hides part of itself from every side: a pipeline that culled nothing
        // (or a converged run that never converged on anything) would show 0 here.
        EXPECT_GT(row["converged_occluded_fraction"].get<double>(), 0.0) << row.dump();
    }
    // At rest the moving pipeline is the converging one: it too must cull.
    EXPECT_GT(j["speeds"][0]["occluded_fraction"].get<double>(), 0.0) << j.dump();
}

TEST(EvalTemporalCli, TextOutputHasOneRowPerSpeed) {
    const CliRun r = run("eval temporal teapot --speeds 0,5 --frames 2 --size 32x32 --tess 1");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("32 patches, 2 frames per speed"), std::string::npos) << r.out;
    int lines = 0;
    for (char c : r.out) lines += c == '\n';
    EXPECT_EQ(lines, 4) << r.out;  // header, column names, two speeds
}

TEST(EvalTemporalCli, BadFlagsAreOneLineErrors) {
    const std::string base = "eval temporal teapot --frames 2 --size 16x16 ";
    for (const char* speeds : {"''", "a", "0,-1", "181", "0,,2", "1,", ",1", "nan", "inf", "5x", "0x5", "1e999",
                               "0,1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16"})
        expect_one_line_error(run(base + "--speeds=" + speeds), "--speeds");
    expect_one_line_error(run(base + "--speeds"), "--speeds");
    expect_one_line_error(run("eval temporal teapot --frames 1"), "--frames");
    expect_one_line_error(run("eval temporal teapot --tess 0"), "--tess");
    expect_one_line_error(run("eval temporal teapot --size 0x4"), "--size");
    expect_one_line_error(run("eval temporal teapot --scheme loop"), "--scheme");
    expect_one_line_error(run("eval temporal"), "MODEL");
    expect_one_line_error(run("eval temporal default"), "MODEL");
    expect_one_line_error(run("eval temporal /nonexistent/model.obj"), "/nonexistent/model.obj");
}

TEST(EvalTemporalCli, SixteenSpeedsAndTheLimitsAreAccepted) {
    // The boundaries of the contract: 16 entries, 0 and 180 inclusive, decimals.
    const CliRun r =
        run("eval temporal teapot --frames 2 --size 16x16 --tess 1 --json "
            "--speeds 0,180,0.5,1,2,3,4,5,6,7,8,9,10,11,12,13");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["speeds"].size(), 16u);
    EXPECT_EQ(j["speeds"][1]["degrees_per_frame"].get<double>(), 180.0);
    EXPECT_EQ(j["speeds"][2]["degrees_per_frame"].get<double>(), 0.5);
}
