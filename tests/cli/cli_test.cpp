// The CLI contract: `info` and `cull` JSON shapes and counts, and one-line errors with
// exit status 2 for every kind of bad input.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

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
    EXPECT_GE(j["methods"]["frustum"]["cull_rate"].get<double>(),
              j["methods"]["frustum-disp"]["cull_rate"].get<double>());
}

TEST(Cli, CullWithProceduralDisplacementOnARealModel) {
    const CliRun r = run("cull " + model("bigguy.obj") +
                         " --views 30 --view-mode free --displace procedural "
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
    // bounds cull more (the order of Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for
    // Hardware Tessellation").
    EXPECT_GE(j["methods"]["ptp"]["cull_rate"].get<double>(), j["methods"]["ncone"]["cull_rate"].get<double>());
    EXPECT_GE(j["methods"]["ncone"]["cull_rate"].get<double>(), j["methods"]["tcone"]["cull_rate"].get<double>());
    // Pcnt additionally culls the degenerate lid and bottom patches (Loop, Niessner & Eisenacher §7).
    EXPECT_GE(j["methods"]["ptp-pcnt"]["cull_rate"].get<double>(), j["methods"]["ptp"]["cull_rate"].get<double>());
}

// `--view-mode distance` (cull_eval.h, DistanceViews). Every view holds the whole
// object, so the frustum tests cull nothing; the ground truth still finds no false cull; and the
// eye distance moves the back-patch rates: near eyes (1..1.2 times the containing distance) see
// less of BigGuy than far ones (4..6 times) and cull more with each method.
TEST(Cli, CullDistanceViewsHoldTheObjectAndDistanceMovesTheRates) {
    const std::string common =
        "cull " + model("bigguy.obj") +
        " --views 60 --seed 5 --view-mode distance --methods frustum,frustum-disp,tcone,ncone,ptp --json";
    const CliRun near_run = run(common + " --distance-range 1,1.2");
    const CliRun far_run = run(common + " --distance-range 4,6");
    ASSERT_EQ(near_run.status, 0) << near_run.err;
    ASSERT_EQ(far_run.status, 0) << far_run.err;
    const auto near_j = nlohmann::json::parse(near_run.out);
    const auto far_j = nlohmann::json::parse(far_run.out);
    EXPECT_EQ(near_j["view_mode"], "distance");
    EXPECT_EQ(near_j["view_distribution"]["distance_range"][0].get<double>(), 1.0);
    EXPECT_NEAR(near_j["view_distribution"]["distance_range"][1].get<double>(), 1.2, 1e-6);
    EXPECT_EQ(near_j["view_distribution"]["fovy_degrees"].get<double>(), 45.0);
    // Eye distance in radii is m / sin(22.5 deg): 2.6..3.1 near, 10.5..15.7 far.
    EXPECT_GT(near_j["mean_eye_distance_radii"].get<double>(), 2.6);
    EXPECT_LT(near_j["mean_eye_distance_radii"].get<double>(), 3.2);
    EXPECT_GT(far_j["mean_eye_distance_radii"].get<double>(), 10.4);
    EXPECT_LT(far_j["mean_eye_distance_radii"].get<double>(), 15.8);
    for (const auto* j : {&near_j, &far_j}) {
        for (const char* m : {"frustum", "frustum-disp", "tcone", "ncone", "ptp"})
            EXPECT_EQ((*j)["methods"][m]["false_culls"], 0) << m;
        EXPECT_EQ((*j)["methods"]["frustum"]["cull_rate"].get<double>(), 0.0);
        EXPECT_EQ((*j)["methods"]["frustum-disp"]["cull_rate"].get<double>(), 0.0);
    }
    for (const char* m : {"tcone", "ncone", "ptp"}) {
        EXPECT_GT(far_j["methods"][m]["cull_rate"].get<double>(), 0.1) << m;
        EXPECT_GT(near_j["methods"][m]["cull_rate"].get<double>(), far_j["methods"][m]["cull_rate"].get<double>()) << m;
    }
    // Without --distance-range the default range 1..3 is reported.
    const CliRun d = run("cull teapot --views 2 --view-mode distance --methods tcone --json");
    ASSERT_EQ(d.status, 0) << d.err;
    const auto dj = nlohmann::json::parse(d.out);
    EXPECT_EQ(dj["view_distribution"]["distance_range"][0].get<double>(), 1.0);
    EXPECT_EQ(dj["view_distribution"]["distance_range"][1].get<double>(), 3.0);
}

TEST(Cli, CullDistanceRangeBadValuesAreOneLine) {
    for (const char* bad : {"0.5,2", "3,2", "3", "1,2,3", "nan,3", "1,inf", "1,", ",2", "''", "1,1001", "a,b"})
        expect_one_line_error(run(std::string("cull teapot --views 1 --view-mode distance --distance-range ") + bad),
                              "--distance-range");
    expect_one_line_error(run("cull teapot --views 1 --view-mode free --distance-range 1,2"), "--distance-range");
    expect_one_line_error(run("cull teapot --views 1 --distance-range 1,2"), "--distance-range");
}

TEST(Cli, BackPatchMethodsRefuseDisplacement) {
    expect_one_line_error(run("cull teapot --methods ptp --displace procedural --views 1 --json"), "--displace");
}

// Flags: every numeric or string option of every command is parsed strictly
// (tools/cli_options.h). Each bad value is one line on stderr naming the flag, exit status 2.
// The GPU commands' flags are checked as they are parsed, before any OpenGL context exists, so
// they are tested here too. The old CLI accepted most of these: `--views 0` ran with rate 0,
// `--seed -1` wrapped to 2^64-1, `1e23` clamped, `--displace-scale -1` meant the default, an
// empty `--displace` or a scale without a map were ignored, integers took octal and hex.
TEST(Cli, EveryNumericAndStringFlagRejectsBadValues) {
    struct Case {
        const char* command;  // everything but the bad option
        const char* flag;
        std::vector<const char*> values;  // as the shell sees them (quoted where needed)
    };
    const std::string bigguy = model("bigguy.obj");
    const Case cases[] = {
        {"info teapot", "--split", {"-1", "5", "1.5", "0x1", "' 1'", "''", "1e0", "+1", "99999999999999999999"}},
        {"info teapot", "--scheme", {"''", "ACC", "loop"}},
        {"cull teapot --views 1", "--seed", {"-1", "1e23", "18446744073709551616", "0x10", "+5", "''", "1.0"}},
        {"cull teapot", "--views", {"0", "-1", "10000001", "1e3", "99999999999999999999", "''", "nan"}},
        {"cull teapot --views 1 --methods frustum --displace procedural",
         "--displace-scale",
         {"-1", "nan", "inf", "-inf", "1e999", "''", "1e10", "0x1p3", "'1 '"}},
        {"cull teapot --views 1 --methods frustum", "--displace", {"''"}},
        {"cull teapot --views 1", "--methods", {"''", "frustum,,ncone", "frustum,frustum", "frustum,", ",frustum"}},
        {"cull teapot --views 1", "--view-mode", {"''", "Free"}},
        {"render teapot", "--frames", {"0", "1001", "-1", "2.5", "''"}},
        {"render teapot", "--tess", {"0", "65", "nan", "08x"}},
        {"render teapot", "--split", {"5", "-0x1"}},
        {"render teapot", "--size", {"0x64", "64x", "8193x1", "64x64x1", "-1x-1", "1e2x1", "''"}},
        {"render teapot", "--cull", {"''", "All"}},
        {"render teapot", "--backpatch", {"''", "cone"}},
        {"view teapot", "--frames", {"-1", "1000001"}},
        {"view teapot --frames 1", "--tess", {"0", "65"}},
        {"view teapot --frames 1", "--size", {"0x0", "x"}},
        {"eval occlusion teapot", "--views", {"0", "100001"}},
        {"eval occlusion teapot", "--seed", {"-1", "1e23"}},
        {"eval occlusion teapot", "--max-frames", {"1", "101"}},
        {"eval occlusion teapot", "--tess", {"0"}},
        {"eval occlusion teapot", "--size", {"1x0"}},
        {"eval displaced teapot", "--views", {"0"}},
        {"eval displaced teapot", "--seed", {"-1"}},
        {"eval displaced teapot", "--displace", {"''"}},
        {"eval displaced teapot", "--displace-scale", {"-1", "nan", "inf", "1e10"}},
        {"eval displaced teapot", "--tess", {"65"}},
        {"demo", "--frames", {"1", "101", "-6"}},
        {"demo", "--tess", {"0", "65"}},
        {"demo", "--size", {"''", "64"}},
        {"demo", "--out-dir", {"''"}},
    };
    for (const Case& c : cases)
        for (const char* value : c.values) {
            SCOPED_TRACE(std::string(c.command) + " " + c.flag + " " + value);
            expect_one_line_error(run(std::string(c.command) + " " + c.flag + " " + value), c.flag);
        }
    // Positional MODEL: empty.
    for (const char* command : {"info", "cull", "render", "view", "eval occlusion", "eval displaced"}) {
        SCOPED_TRACE(command);
        expect_one_line_error(run(std::string(command) + " ''"), "MODEL");
    }
    // A scale without a map would be ignored: `cull` (no default map) refuses it.
    expect_one_line_error(run("cull teapot --views 1 --displace-scale 0.1"), "--displace-scale");
}

TEST(Cli, BadFlagValuesAreQuotedOnOneLine) {
    // A control byte or a newline in a value must not break the one-line error.
    expect_one_line_error(run("cull teapot --views \"$(printf '1\\n2')\""),
                          "--views: expected an integer in 1..10000000");
    expect_one_line_error(run("render teapot --size \"$(printf '64\\nx64')\""), "--size");
    expect_one_line_error(run("info teapot --scheme \"$(printf 'a\\033[31m')\""), "--scheme: expected one of acc|osd");
    const CliRun r = run("cull teapot --views 1 --methods \"$(printf 'frustum,x\\001y')\"");
    expect_one_line_error(r, "--methods: unknown cull method 'x\\x01y'");
}

TEST(Cli, StrictFlagsStillTakeEveryValidValue) {
    // The range ends: seed 0 and 2^64-1, one view, split 4 (info is fast).
    CliRun r = run("cull teapot --views 1 --seed 18446744073709551615 --methods frustum --json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["seed"].get<std::uint64_t>(), 18446744073709551615ull);
    EXPECT_EQ(nlohmann::json::parse(r.out)["views"], 1);
    r = run("cull teapot --views 1 --seed 0 --methods frustum --json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["seed"], 0);
    r = run("info teapot --split 4 --json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["patches"], 32 * 256);
    // Reals: exponent notation, 0 (no displacement) and the upper end.
    for (const char* scale : {"2.5e-2", "0", "1e9"}) {
        r = run(std::string("cull teapot --views 2 --methods frustum --displace procedural --displace-scale ") + scale +
                " --json");
        ASSERT_EQ(r.status, 0) << scale << ": " << r.err;
        EXPECT_EQ(nlohmann::json::parse(r.out)["methods"]["frustum"]["false_culls"], 0) << scale;
    }
}

// Output paths: checked before any work (no model loaded, no OpenGL context), one line
// naming the flag and the path, exit 2. The old `demo --out-dir /proc/nonexistent` rendered the
// whole job and then exited 3 ("internal error: filesystem error").
TEST(Cli, OutputPathsAreCheckedBeforeTheWork) {
    const std::string file = write_file("a_file", "x");
    const std::string& dir = scratch_dir();
    std::filesystem::create_directories(dir + "/blocked/frame.png");  // a directory where a file goes
    // demo: the directory cannot be created, its parent is a file, or one of its files cannot be written.
    expect_one_line_error(run("demo --out-dir /proc/nonexistent"),
                          "--out-dir: cannot create directory '/proc/nonexistent'");
    expect_one_line_error(run("demo --out-dir " + file + "/sub"),
                          "--out-dir: cannot create directory '" + file + "/sub'");
    expect_one_line_error(run("demo --out-dir " + file), "--out-dir: cannot create directory '" + file + "'");
    expect_one_line_error(run("demo --out-dir " + dir + "/blocked"),
                          "--out-dir: cannot write '" + dir + "/blocked/frame.png': is a directory");
    // render --out and view --screenshot: a missing directory, a directory, a file as the parent, empty.
    // "FLAG: cannot write 'PATH': WHY"
    const auto cannot_write = [](const std::string& flag, const std::string& path, const char* why) {
        std::string message = flag;
        message += ": cannot write '";
        message += path;
        message += "': ";
        message += why;
        return message;
    };
    for (const std::string command : {"render teapot --frames 1 --size 8x8", "view teapot --frames 1 --size 8x8"}) {
        const std::string flag = command.rfind("render", 0) == 0 ? "--out" : "--screenshot";
        SCOPED_TRACE(command);
        std::string with_flag = command;  // "COMMAND FLAG "
        with_flag += ' ';
        with_flag += flag;
        with_flag += ' ';
        expect_one_line_error(run(with_flag + "/nonexistent/dir/x.png"),
                              cannot_write(flag, "/nonexistent/dir/x.png", "No such file or directory"));
        expect_one_line_error(run(with_flag + dir), cannot_write(flag, dir, "is a directory"));
        expect_one_line_error(run(with_flag + file + "/x.png"), cannot_write(flag, file + "/x.png", "Not a directory"));
        expect_one_line_error(run(with_flag + "''"), flag + ": empty path");
    }
}

TEST(Cli, OutputPathProbeLeavesNothingBehind) {
    // The probe file is created and removed: a run that fails later (here at --split, in the
    // command's own checks after parsing, still before OpenGL) leaves no file, and an existing
    // file is left as it was.
    const std::string png = scratch_dir() + "/probe.png";
    std::filesystem::remove(png);
    expect_one_line_error(run("render default --split 1 --out " + png), "--split");
    EXPECT_FALSE(std::filesystem::exists(png));
    const std::string existing = write_file("existing.png", "old");
    expect_one_line_error(run("render default --split 1 --out " + existing), "--split");
    EXPECT_EQ(slurp(existing), "old");
}
