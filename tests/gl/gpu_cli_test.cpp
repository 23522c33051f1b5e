// The CLI contract of the GPU pipeline: `render --json` shape and keys, `--verify`
// finding no false culls in any cull mode (strict: compare_frames against the unculled render of
// every frame) and catching the ones back-patch culling makes on an open surface, one-line errors
// with exit status 2 (bad flags, missing OpenGL), the main job writing both PNGs, and
// `eval occlusion --json`, `eval displaced --json`. In the gl suite because it needs OpenGL (the cli suite also runs
// under ASan with leak detection, which would report Mesa's own allocations). Everything runs on Mesa llvmpipe at tiny
// sizes (64x64; the teapot, BigGuy at tessellation level 2).
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

// A small render of the teapot scene (512 patches after two splits: enough for occlusion).
const std::string kSmallTeapot = "render teapot --split 2 --size 64x64 --tess 4 ";

bool is_png(const std::string& path) {
    const std::string bytes = slurp(path);
    return bytes.size() > 8 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0;
}

}  // namespace

TEST(GpuCli, RenderJsonHasTheContractKeys) {
    const std::string png = scratch_dir() + "/render.png";
    std::filesystem::remove(png);
    // BigGuy, a closed surface, so `all` includes the back-patch test.
    const CliRun r = run("render " + model("bigguy.obj") +
                         " --size 64x64 --tess 2 --frames 3 --cull all --backpatch tcone --out " + png + " --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_TRUE(j.contains("frames"));
    ASSERT_TRUE(j.contains("false_culls"));
    EXPECT_EQ(j["verified"], false);
    EXPECT_EQ(j["false_culls"], 0);
    EXPECT_EQ(j["backpatch"], "tcone");
    const std::size_t patches = j["patches"];
    EXPECT_EQ(patches, 1450u);
    ASSERT_EQ(j["frames"].size(), 3u);
    for (int f = 0; f < 3; ++f) {
        const auto& frame = j["frames"][f];
        EXPECT_EQ(frame["frame"], f);
        for (const char* key :
             {"pass1_drawn", "pass2_drawn", "frustum_culled", "backpatch_culled", "occlusion_culled", "false_culls"})
            ASSERT_TRUE(frame.contains(key) && frame[key].is_number_unsigned()) << key << " in " << frame.dump();
        for (const char* key : {"pass1", "hiz", "cull", "pass2"})
            ASSERT_TRUE(frame["ms"].contains(key) && frame["ms"][key].is_number()) << key;
        // Every patch is culled for exactly one reason or drawn in one of the passes (pass 2 draws
        // exactly the newly visible ones).
        const std::size_t culled = frame["frustum_culled"].get<std::size_t>() +
                                   frame["backpatch_culled"].get<std::size_t>() +
                                   frame["occlusion_culled"].get<std::size_t>();
        EXPECT_EQ(culled + frame["visible"].get<std::size_t>(), patches) << frame.dump();
        EXPECT_EQ(frame["pass2_drawn"], frame["newly_visible"]);
    }
    // BigGuy seen from outside: some patches face away, some are hidden.
    EXPECT_GT(j["frames"][2]["backpatch_culled"].get<std::size_t>(), 0u);
    EXPECT_GT(j["frames"][2]["occlusion_culled"].get<std::size_t>(), 0u);
    EXPECT_TRUE(is_png(png));
}

TEST(GpuCli, VerifyFindsNoFalseCullsInAnyMode) {
    // BigGuy (1450 patches), a closed surface: back-patch culling is conservative only there (see
    // VerifyCatchesBackFacingPatchesSeenThroughTheTeapotsLidGap).
    const std::string render = "render " + model("bigguy.obj") + " --size 64x64 --tess 2 --frames 3 --verify --json ";
    struct Case {
        const char* args;
        const char* must_cull;  // a count that must be > 0 in the last frame ("" = none)
    };
    const Case cases[] = {
        {"--cull none", ""},
        {"--cull frustum", ""},
        {"--cull backpatch --backpatch tcone", "backpatch_culled"},
        {"--cull backpatch --backpatch ncone", "backpatch_culled"},
        {"--cull backpatch --backpatch ptp", "backpatch_culled"},
        {"--cull occlusion", "occlusion_culled"},
        {"--cull all --backpatch ncone", "occlusion_culled"},
        {"--cull all --backpatch ptp", "backpatch_culled"},
    };
    for (const Case& c : cases) {
        const CliRun r = run(render + c.args);
        ASSERT_EQ(r.status, 0) << c.args << ": " << r.err;
        const auto j = nlohmann::json::parse(r.out);
        EXPECT_EQ(j["verified"], true);
        EXPECT_EQ(j["false_culls"], 0) << c.args;
        for (const auto& frame : j["frames"]) {
            EXPECT_EQ(frame["false_culls"], 0) << c.args << " frame " << frame["frame"];
            EXPECT_FALSE(frame.contains("false_culled_patches")) << c.args;
            EXPECT_TRUE(frame["ms"].contains("reference"));
        }
        if (*c.must_cull) {
            EXPECT_GT(j["frames"][2][c.must_cull].get<std::size_t>(), 0u) << c.args;
        }
        if (std::string(c.args) == "--cull none") {
            EXPECT_EQ(j["frames"][2]["pass1_drawn"], 1450) << "cull none must draw every patch";
        }
    }
}

TEST(GpuCli, VerifyCatchesBackFacingPatchesSeenThroughTheTeapotsLidGap) {
    // The teapot is not closed: its lid sits loose inside the rim, and from above the inside of the
    // far upper body (patches 4-7, whose outside faces away) shows through the gap. An explicit
    // --cull backpatch still runs there (with a warning): its test culls those patches although
    // they contribute pixels, and --verify must report them, and fail: exit status 1, as the main
    // job does (it once exited 0).
    const CliRun r = run(kSmallTeapot + "--frames 3 --cull backpatch --backpatch tcone --verify --json");
    ASSERT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("warning: render: teapot is not a closed solid"), std::string::npos) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_GT(j["false_culls"].get<std::size_t>(), 0u);
    std::size_t listed = 0;
    for (const auto& frame : j["frames"]) {
        if (!frame.contains("false_culled_patches")) continue;
        for (const auto& index : frame["false_culled_patches"]) {
            const std::size_t parent = index.get<std::size_t>() / 16;  // two 1-to-4 splits
            EXPECT_GE(parent, 4u) << frame.dump();
            EXPECT_LE(parent, 7u) << frame.dump();
            ++listed;
        }
    }
    EXPECT_EQ(listed, j["false_culls"].get<std::size_t>());
}

TEST(GpuCli, AllLeavesBackPatchCullingOutOnOpenSurfaces) {
    // The same teapot frames with --cull all: no back-patch test, so nothing is falsely culled.
    const CliRun r = run(kSmallTeapot + "--frames 3 --cull all --backpatch tcone --verify --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["backpatch"], "off");
    EXPECT_EQ(j["false_culls"], 0);
    for (const auto& frame : j["frames"]) EXPECT_EQ(frame["backpatch_culled"], 0);
    EXPECT_GT(j["frames"][2]["occlusion_culled"].get<std::size_t>(), 0u);
}

TEST(GpuCli, VerifyOnTheDefaultSceneCullsByFrustumWithoutFalseCulls) {
    // The default scene (8226 patches) at a tiny size: its camera path leaves characters partly
    // outside the view, so frustum culling has work.
    const CliRun r = run("render default --frames 2 --size 64x36 --tess 1 --cull all --verify --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["patches"], 3 * 1450 + 3 * 1292);
    EXPECT_EQ(j["false_culls"], 0);
    EXPECT_GT(j["frames"][1]["frustum_culled"].get<std::size_t>(), 0u);
    EXPECT_GT(j["frames"][1]["occlusion_culled"].get<std::size_t>(), 0u);
}

TEST(GpuCli, AggressiveModeSkipsTheSecondPass) {
    const CliRun r = run(kSmallTeapot + "--frames 2 --cull occlusion --aggressive --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["aggressive"], true);
    for (const auto& frame : j["frames"]) EXPECT_EQ(frame["pass2_drawn"], 0);
}

TEST(GpuCli, BadRenderFlagsAreOneLineErrors) {
    expect_one_line_error(run("render teapot --cull sideways --json"), "--cull");
    expect_one_line_error(run("render teapot --backpatch cones --json"), "--backpatch");
    expect_one_line_error(run("render teapot --size 64 --json"), "--size");
    expect_one_line_error(run("render teapot --size 0x64 --json"), "--size");
    expect_one_line_error(run("render teapot --size 64xfoo --json"), "--size");
    expect_one_line_error(run("render teapot --tess 0 --json"), "--tess");
    expect_one_line_error(run("render teapot --tess 65 --json"), "--tess");
    expect_one_line_error(run("render teapot --frames 0 --json"), "--frames");
    expect_one_line_error(run("render teapot --scheme loop --json"), "--scheme");
    expect_one_line_error(run("render teapot --bogus --json"), "--bogus");
    expect_one_line_error(run("render /nonexistent/model.obj --json"), "/nonexistent/model.obj: cannot open file");
    expect_one_line_error(run("render default --split 1 --json"), "--split");
    expect_one_line_error(run("render teapot --size 8x8 --frames 1 --out /nonexistent/dir/x.png --json"),
                          "/nonexistent/dir/x.png");
    expect_one_line_error(run("demo --size big"), "--size");
    expect_one_line_error(run("demo --frames 1"), "--frames");
    expect_one_line_error(run("eval"), "eval");
    expect_one_line_error(run("eval occlusion"), "MODEL");
    expect_one_line_error(run("eval occlusion teapot --views 0"), "--views");
    expect_one_line_error(run("eval sideways teapot"), "sideways");
    expect_one_line_error(run("eval occlusion /nonexistent/model.obj"), "/nonexistent/model.obj");
}

// eval displaced (Table 1 of Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation"):
// six rows with the contract's keys, no false culls against
// the unculled displaced render (converged depth and running pipeline), and the nesting that is a theorem: a CAF with a
// cone lies inside the CAF without one (DisplacedBounds.CafWithAConeLiesInsideTheFullCaf), so per view it culls at
// least as much (a smaller rectangle reads a finer Hi-Z level, whose max is not larger).
TEST(GpuCli, EvalDisplacedGivesSixRowsWithoutFalseCulls) {
    const CliRun r = run("eval displaced " + model("monsterfrog.obj") + " --views 4 --size 96x96 --tess 2 --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["rows"].size(), 6u);
    std::map<std::string, double> rate;
    for (const auto& row : j["rows"]) {
        for (const char* key : {"bound", "cone", "cull_rate", "false_culls", "pipeline_cull_rate", "pipeline_frames",
                                "pipeline_false_culls"})
            ASSERT_TRUE(row.contains(key)) << row.dump();
        EXPECT_EQ(row["false_culls"], 0) << row.dump();
        // The running pipeline (its own Hi-Z, displaced patches tested by their bound in the frame).
        EXPECT_EQ(row["pipeline_false_culls"], 0) << row.dump();
        EXPECT_GT(row["pipeline_cull_rate"].get<double>(), 0.0) << row.dump();
        EXPECT_LE(row["pipeline_cull_rate"].get<double>(), 1.0) << row.dump();
        EXPECT_GE(row["pipeline_frames"].get<double>(), 1.0) << row.dump();
        const double c = row["cull_rate"];
        EXPECT_GE(c, 0.0);
        EXPECT_LE(c, 1.0);
        rate[row["bound"].get<std::string>() + "/" + row["cone"].get<std::string>()] = c;
    }
    ASSERT_EQ(rate.size(), 6u);
    EXPECT_GT(rate["caf/full"], 0.0) << "nothing culled: the comparison below would be vacuous";
    EXPECT_GE(rate["caf/acon"], rate["caf/full"]);
    EXPECT_GE(rate["caf/con"], rate["caf/full"]);
}

TEST(GpuCli, EvalDisplacedBadInputIsAOneLineError) {
    expect_one_line_error(run("eval displaced teapot --displace /nonexistent/height.png --views 1"),
                          "/nonexistent/height.png");
    expect_one_line_error(run("eval displaced teapot --views 0"), "--views");
    expect_one_line_error(run("eval displaced teapot --displace-scale nan --views 1"), "--displace-scale");
}

TEST(GpuCli, MissingOpenGlIsAOneLineError) {
    // libglvnd's EGL finds no vendor library (as on a machine without Mesa's EGL): the GPU
    // commands must say so in one line and exit with status 2, not crash.
    const std::string no_egl = "__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/egl_vendor.json";
    expect_one_line_error(run("render teapot --frames 1 --size 8x8 --json", no_egl), "EGL");
    expect_one_line_error(run("eval occlusion teapot --views 1 --size 8x8 --json", no_egl), "EGL");
    expect_one_line_error(run("demo --size 8x8 --frames 2", no_egl), "EGL");
}

TEST(GpuCli, MainJobWritesFrameAndCullImages) {
    const std::string dir = scratch_dir() + "/main_job";
    std::filesystem::remove_all(dir);
    // The main job's code path (`patchcull` without arguments runs `demo` with its defaults) at a
    // small size, two frames.
    const CliRun r = run("demo --size 96x54 --frames 2 --tess 2 --city-frames 2 --out-dir " + dir);
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    EXPECT_TRUE(is_png(dir + "/frame.png"));
    EXPECT_TRUE(is_png(dir + "/cull.png"));
    for (const char* method : {"none (reference)", "frustum", "backpatch tcone", "backpatch ncone", "backpatch ptp",
                               "occlusion", "all (tcone)", "auto (tcone)", "(objects culled per frame: ",
                               "patchcull city: ", "\nnone ", "\nfrustum ", "\nbvh ", "\nbvh+backface "})
        EXPECT_NE(r.out.find(method), std::string::npos) << method << " missing from\n" << r.out;
    EXPECT_NE(r.out.find("in total: 0 (must be 0)"), std::string::npos) << r.out;
}

TEST(GpuCli, EvalOcclusionOnTheTeapot) {
    const CliRun r = run("eval occlusion teapot --split 1 --views 3 --size 64x64 --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["views"], 3);
    EXPECT_EQ(j["patches"], 128);
    EXPECT_EQ(j["false_culls"], 0);
    const double occluded = j["occluded_fraction"];
    EXPECT_GT(occluded, 0.0);  // the teapot's inside (body seen through nothing, lid, spout) hides patches
    EXPECT_LT(occluded, 1.0);
    EXPECT_LE(j["occluded_fraction_min"].get<double>(), occluded);
    EXPECT_GE(j["occluded_fraction_max"].get<double>(), occluded);
    EXPECT_EQ(j["frustum_fraction"], 0.0);           // every view contains the whole object
    EXPECT_GE(j["frames_mean"].get<double>(), 2.0);  // stability needs two equal frames
    EXPECT_TRUE(j["backpatch_fraction"].contains("tcone"));
}
