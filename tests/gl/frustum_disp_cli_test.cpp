// `render --frustum hull|aabb`: the pipeline's frustum test chosen on the command line.
// With aabb (FrustumDispPass, Sathe's box grown by max |D|) `--verify` finds no false culls against
// the unculled render on BigGuy half outside the view, for acc and osd patches, undisplaced and
// displaced (procedural map; frustum alone and with the two-pass occlusion pipeline), and the
// test culls; the JSON reports the choice; a bad value is a one-line error naming --frustum.
// scripts/sathe_study.py (docs/PERFORMANCE.md, "Sathe's study"): its camera setups give what the
// study claims (nothing culled with the whole object in view, about half culled in the other),
// and bad input is one line naming the flag. `view --frustum` reaches the pipeline (xvfb).
// Tiny sizes (64x36, level 1-2, 2 frames) on llvmpipe: about 10 s in all.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

// BigGuy (1 high) with a still camera 1.8 away whose view centre is 1.75 to its side: about half
// of the patches lie outside the frustum (the setup of the Sathe study, scripts/sathe_study.py).
std::string half_out_scene(const std::string& scheme) {
    return write_file(
        "sathe_half_" + scheme + ".json",
        R"({"name":"sathe_half","objects":[{"model":")" + model("bigguy.obj") + R"(","scheme":")" + scheme +
            R"(","transform":{"position":[0,0,0],"height":1},"animation":{"deform":false}}],)"
            R"("camera":{"orbit":{"target":[1.75,0.5,0],"distance":1.8,"height":0,"degrees_per_frame":0}}})");
}

nlohmann::json render_json(const std::string& args) {
    const CliRun r = run("render " + args + " --frames 2 --size 64x36 --tess 2 --verify --json");
    EXPECT_EQ(r.status, 0) << args << ": " << r.err;
    return r.status == 0 ? nlohmann::json::parse(r.out) : nlohmann::json();
}

std::size_t last_frustum_culled(const nlohmann::json& j) {
    return j["frames"].back()["frustum_culled"].get<std::size_t>();
}

}  // namespace

TEST(FrustumDispCli, AabbVerifiesWithoutFalseCullsAndCulls) {
    for (const std::string scheme : {"acc", "osd"}) {
        SCOPED_TRACE(scheme);
        const std::string scene = half_out_scene(scheme);
        const nlohmann::json aabb = render_json(scene + " --cull frustum --frustum aabb");
        ASSERT_TRUE(aabb.is_object());
        EXPECT_EQ(aabb["frustum"], "aabb");
        EXPECT_EQ(aabb["false_culls"], 0);
        const std::size_t culled = last_frustum_culled(aabb);
        EXPECT_GT(culled, aabb["patches"].get<std::size_t>() / 5);
        // The box contains the control points, so it culls no more than the hull test (the
        // default; counts, as rounding may differ at a plane).
        const nlohmann::json hull = render_json(scene + " --cull frustum");
        ASSERT_TRUE(hull.is_object());
        EXPECT_EQ(hull["frustum"], "hull");
        EXPECT_EQ(hull["false_culls"], 0);
        EXPECT_LE(culled, last_frustum_culled(hull));
    }
}

TEST(FrustumDispCli, AabbBoundsDisplacedPatches) {
    const std::string scene = half_out_scene("acc");
    // Frustum alone: the box grown by max |D| is the only frustum test of the displaced patches.
    const nlohmann::json frustum = render_json(scene + " --cull frustum --frustum aabb --displace procedural");
    ASSERT_TRUE(frustum.is_object());
    EXPECT_EQ(frustum["displaced_patches"], frustum["patches"]);
    EXPECT_EQ(frustum["false_culls"], 0);
    EXPECT_GT(last_frustum_culled(frustum), 0u);
    // Two-pass pipeline: the displaced bound still runs for the Hi-Z test.
    const nlohmann::json all = render_json(scene + " --cull all --frustum aabb --displace procedural");
    ASSERT_TRUE(all.is_object());
    EXPECT_EQ(all["false_culls"], 0);
    EXPECT_GT(last_frustum_culled(all), 0u);
}

TEST(FrustumDispCli, BadFrustumValueIsAOneLineError) {
    expect_one_line_error(run("render teapot --frustum box --json"), "--frustum");
    expect_one_line_error(run("render teapot --frustum --json"), "--frustum");
    expect_one_line_error(run("view teapot --frustum box"), "--frustum");
}

TEST(FrustumDispCli, ViewRunsTheChosenTest) {
    // `view --frames N` without a script runs render's frames in a window (xvfb here) and prints a
    // line per frame: its frustum count must be render's for the same test, and the two tests
    // must differ on this view (else the flag could be ignored unnoticed).
    ASSERT_EQ(std::system("command -v xvfb-run >/dev/null 2>&1"), 0) << "xvfb-run is missing (scripts/install-deps.sh)";
    const std::string scene = half_out_scene("acc");
    std::size_t culled[2] = {};
    int i = 0;
    const std::string common = scene + " --frames 2 --size 64x36 --tess 2 --cull frustum --frustum ";
    for (const std::string test : {"hull", "aabb"}) {
        SCOPED_TRACE(test);
        const std::string args = common + test;
        const CliRun v = run("view " + args, "xvfb-run -a -s '-screen 0 1280x1024x24'");
        ASSERT_EQ(v.status, 0) << v.err;
        const CliRun r = run("render " + args + " --json");
        ASSERT_EQ(r.status, 0) << r.err;
        culled[i] = last_frustum_culled(nlohmann::json::parse(r.out));
        const std::string expected = "frame 1: drawn " + std::to_string(1450 - culled[i]) +
                                     " + 0 of 1450; culled frustum " + std::to_string(culled[i]) + ",";
        EXPECT_NE(v.out.find(expected), std::string::npos) << v.out;
        ++i;
    }
    EXPECT_NE(culled[0], culled[1]);
}

namespace {

// python3 scripts/sathe_study.py ARGS, with the build's CLI unless args name one.
CliRun run_study(const std::string& args, bool with_cli = true) {
    const std::string out = scratch_dir() + "/study_stdout", err = scratch_dir() + "/study_stderr";
    const std::string cmd = std::string("python3 ") + PATCHCULL_SOURCE_DIR + "/scripts/sathe_study.py " +
                            (with_cli ? std::string("--cli ") + PATCHCULL_CLI + " " : std::string()) + args + " >" +
                            out + " 2>" + err + " </dev/null";
    const int raw = std::system(cmd.c_str());
    CliRun r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

}  // namespace

TEST(FrustumDispCli, SatheStudySetupsCullNothingAndAboutHalf) {
    const std::string json = scratch_dir() + "/sathe_study.json";
    const CliRun r = run_study("--scenes bigguy --levels 1 --size 64x36 --frames 2 --json " + json);
    ASSERT_EQ(r.status, 0) << r.err;
    std::ifstream in(json);
    const auto j = nlohmann::json::parse(in);
    ASSERT_EQ(j["rows"].size(), 2u);
    for (const auto& row : j["rows"]) {
        const double patches = row["patches"].get<double>();
        for (const char* mode : {"hull", "aabb"}) {
            const double culled = row[std::string(mode) + "_culled"].get<double>() / patches;
            if (row["setup"] == "whole") {
                EXPECT_EQ(culled, 0.0) << mode;
            } else {
                EXPECT_GT(culled, 0.3) << mode;
                EXPECT_LT(culled, 0.7) << mode;
            }
            EXPECT_GT(row[std::string(mode) + "_ratio"].get<double>(), 0.0);
        }
        EXPECT_EQ(row["none_culled"], 0);
    }
}

TEST(FrustumDispCli, SatheStudyBadInputIsAOneLineError) {
    expect_one_line_error(run_study("--levels two"), "--levels");
    expect_one_line_error(run_study("--scenes teapot"), "--scenes");
    expect_one_line_error(run_study("--size 64"), "--size");
    expect_one_line_error(run_study("--bogus 1"), "--bogus");
    expect_one_line_error(run_study("--cli /nonexistent/patchcull", false), "/nonexistent/patchcull");
}
