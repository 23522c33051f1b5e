// The CLI contract (issue 2): `info` and `cull` JSON shapes and counts, and one-line errors with
// exit status 2 for every kind of bad input.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_util.h"

using namespace patchcull::cli_test;

TEST(Cli, InfoBigGuyAcc) {
    const CliRun r = run("info " + model("bigguy.obj") + " --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["patches"], 1450);
    EXPECT_EQ(j["scheme"], "acc");
    EXPECT_EQ(j["extraordinary_patches"], 592);
}

TEST(Cli, InfoMonsterFrogSplitOnce) {
    const CliRun r = run("info " + model("monsterfrog.obj") + " --scheme acc --split 1 --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["patches"], 5168);
    EXPECT_EQ(j["extraordinary_patches"], 4 * 764);
}

TEST(Cli, InfoOsdScheme) {
    const CliRun r = run("info " + model("bigguy.obj") + " --scheme osd --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["scheme"], "osd");
    EXPECT_GT(j["patches"].get<int>(), 1450);  // adaptive refinement around extraordinary vertices
    EXPECT_GT(j["extraordinary_patches"].get<int>(), 0);
}

TEST(Cli, InfoTeapot) {
    const CliRun r = run("info teapot --json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["patches"], 32);
}

TEST(Cli, CullPrintsTheContractShapeWithNoFalseCulls) {
    const CliRun r = run("cull teapot --views 50 --seed 3 --view-mode free --methods frustum,frustum-disp --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["model"], "teapot");
    EXPECT_EQ(j["patches"], 32);
    EXPECT_EQ(j["views"], 50);
    for (const char* m : {"frustum", "frustum-disp"}) {
        const auto& mj = j["methods"][m];
        ASSERT_TRUE(mj.is_object()) << m;
        EXPECT_GE(mj["cull_rate"].get<double>(), 0.0);
        EXPECT_LE(mj["cull_rate"].get<double>(), 1.0);
        EXPECT_GT(mj["cull_rate"].get<double>(), 0.05) << m << ": free views must cull something";
        EXPECT_EQ(mj["false_culls"], 0) << m;
        EXPECT_GT(mj["ns_per_patch"].get<double>(), 0.0);
    }
    // frustum tests the convex hull, frustum-disp its AABB: the hull is never culled less.
    EXPECT_GE(j["methods"]["frustum"]["cull_rate"].get<double>(), j["methods"]["frustum-disp"]["cull_rate"].get<double>());
}

TEST(Cli, CullWithProceduralDisplacementOnARealModel) {
    const CliRun r = run("cull " + model("bigguy.obj") + " --views 30 --view-mode free --displace procedural "
                      "--displace-scale 0.5 --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["methods"]["frustum"]["false_culls"], 0);
    EXPECT_EQ(j["methods"]["frustum-disp"]["false_culls"], 0);
}

TEST(Cli, MissingFile) {
    expect_one_line_error(run("info /nonexistent/model.obj --json"), "/nonexistent/model.obj: cannot open file");
}

TEST(Cli, MalformedObj) {
    const std::string path = write_file("malformed.obj", "v 0 0 0\nv 1 0 0\nv 1 x 0\nf 1 2 3\n");
    expect_one_line_error(run("info " + path + " --json"), path + ":3: malformed number 'x'");
}

TEST(Cli, NonFiniteCoordinates) {
    const std::string path = write_file("nan.obj", "v 0 0 0\nv 1 0 0\nv 1 inf 0\nf 1 2 3\n");
    expect_one_line_error(run("cull " + path + " --views 1 --json"), path + ":3: non-finite coordinate 'inf'");
}

TEST(Cli, FaceIndexOutOfRange) {
    const std::string path = write_file("range.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 9\n");
    expect_one_line_error(run("info " + path), path + ":5: vertex index 9 out of range (have 4)");
}

TEST(Cli, UnreadableImage) {
    expect_one_line_error(run("cull teapot --views 1 --displace /nonexistent/height.png --json"),
                          "/nonexistent/height.png: cannot read image");
    const std::string garbage = write_file("garbage.png", "this is not a png");
    expect_one_line_error(run("cull teapot --views 1 --displace " + garbage + " --json"),
                          garbage + ": cannot read image");
}

TEST(Cli, UnknownFlagAndBadValues) {
    expect_one_line_error(run("info teapot --bogus-flag"), "--bogus-flag");
    expect_one_line_error(run("cull teapot --methods frustum,warp --json"), "--methods: unknown cull method 'warp'");
    expect_one_line_error(run("cull teapot --view-mode sideways"), "--view-mode");
    expect_one_line_error(run("info teapot --split 9"), "--split");
    expect_one_line_error(run("cull teapot --views -3"), "--views");
    expect_one_line_error(run("cull teapot --displace procedural --displace-scale nan"), "--displace-scale");
    expect_one_line_error(run("frobnicate"), "frobnicate");
}

TEST(Cli, CullBackPatchMethodsOnTheTeapot) {
    const CliRun r = run("cull teapot --methods tcone,ncone,ptp,ptp-pcnt --views 200 --view-mode contain --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    for (const char* m : {"tcone", "ncone", "ptp", "ptp-pcnt"}) {
        EXPECT_EQ(j["methods"][m]["false_culls"], 0) << m;
        EXPECT_GT(j["methods"][m]["cull_rate"].get<double>(), 0.005) << m;
    }
    // The teapot's 32 patches are large and curved: few are wholly back-facing, and the tighter
    // bounds cull more (seed 001's order).
    EXPECT_GE(j["methods"]["ptp"]["cull_rate"].get<double>(), j["methods"]["ncone"]["cull_rate"].get<double>());
    EXPECT_GE(j["methods"]["ncone"]["cull_rate"].get<double>(), j["methods"]["tcone"]["cull_rate"].get<double>());
    // Pcnt additionally culls the degenerate lid and bottom patches (seed 001 §7).
    EXPECT_GE(j["methods"]["ptp-pcnt"]["cull_rate"].get<double>(), j["methods"]["ptp"]["cull_rate"].get<double>());
}

TEST(Cli, BackPatchMethodsRefuseDisplacement) {
    expect_one_line_error(run("cull teapot --methods ptp --displace procedural --views 1 --json"), "--displace");
}
