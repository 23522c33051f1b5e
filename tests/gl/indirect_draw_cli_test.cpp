// `render --draw indirect` (gl_pipeline.h's DrawMode::indirect: CompactPass lists each draw pass's
// survivors and indirect draws issue only those) under the strict id-buffer test: in every frame
// no false cull and every pixel whose id differs from the unculled reference's is a depth tie
// (differing_pixels == depth_ties), and the patches submitted are exactly the patches drawn. Every
// mode: two-pass, aggressive (the flag path's decisions and false culls, pass 2 never issued), the
// fused pass, displaced patches (the default scene's MonsterFrogs), one pass, the object level,
// object occlusion (CHC++ in two passes, stop-and-wait in one), both schemes, at the origin and
// 1e5 units out, and at tessellation 20, where a compacted draw of one command per pass would
// give llvmpipe's garbage triangles (the commands are split as the flag path's draws are).
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

std::string indirect_city() { return std::string(PATCHCULL_SOURCE_DIR) + "/data/scenes/city_small.json"; }

// Two BigGuys (one deforming) behind a wall, a displaced MonsterFrog and a ground, d units out
// along x, seen by an orbit camera (the wall hides a BigGuy in some frames).
std::string indirect_far_scene(double d) {
    const std::string x = std::to_string(d);
    auto at = [&](double dx) { return std::to_string(d + dx); };
    return R"({"name": "indirect_far", "displacement": {"map": "procedural", "scale": 0.03, "size": 64},
 "objects": [
  {"model": "bigguy", "transform": {"position": [)" +
           x + R"(, 0, 0], "yaw_degrees": 200, "height": 1}},
  {"model": "bigguy", "transform": {"position": [)" +
           at(0.4) + R"(, 0, -2.4], "yaw_degrees": 160, "height": 1}, "animation": {"deform": false}},
  {"model": "monsterfrog", "transform": {"position": [)" +
           at(-0.8) + R"(, 0, -1.5], "height": 0.7}, "displaced": true}],
 "environment": [
  {"name": "ground", "quad": [[)" +
           at(-6) + R"(, -0.002, -8], [)" + at(-6) + R"(, -0.002, 4], [)" + at(6) + R"(, -0.002, 4], [)" + at(6) +
           R"(, -0.002, -8]], "one_sided": true},
  {"name": "wall", "box": {"min": [)" +
           at(-0.3) + R"(, 0, -1.3], "max": [)" + at(1.2) + R"(, 1.3, -1.1]}}],
 "camera": {"orbit": {"target": [)" +
           x + R"(, 0.5, -1.2], "distance": 4, "height": 0.8, "start_degrees": 10,
            "degrees_per_frame": 20}, "z_near": 0.05, "z_far": 40}}
)";
}

struct IndirectTotals {
    long submitted = 0, occlusion = 0, objects_culled = 0, false_culls = 0;
};

// `render ARGS --draw D --verify --json` at 96x64: exit 0 (1 with false culls when allowed), "draw"
// reported. strict: every frame has 0 false culls, only depth ties differ from the reference,
// and submits exactly the patches it draws.
IndirectTotals indirect_render(const std::string& args, const std::string& draw = "indirect", bool strict = true) {
    IndirectTotals t;
    const std::string command = "render " + args + " --size 96x64 --draw " + draw + " --verify --json";
    const CliRun r = run(command);
    EXPECT_EQ(r.status, strict ? 0 : 1) << command << "\n" << r.err;
    if (r.out.empty()) return t;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["draw"], draw) << command;
    for (const nlohmann::json& f : j["frames"]) {
        const std::string where = command + ", frame " + f["frame"].dump();
        const long submitted = f["submitted"]["pass1"].get<long>() + f["submitted"]["pass2"].get<long>();
        const long drawn = f["pass1_drawn"].get<long>() + f["pass2_drawn"].get<long>();
        t.submitted += submitted;
        t.occlusion += f["occlusion_culled"].get<long>();
        t.objects_culled += f["objects"]["patches_culled"].get<long>();
        t.false_culls += f["false_culls"].get<long>();
        if (!strict) continue;
        EXPECT_EQ(f["false_culls"], 0) << where << ": " << f.value("false_culled_patches", nlohmann::json()).dump();
        EXPECT_EQ(f["differing_pixels"], f["depth_ties"]) << where;
        if (draw == "indirect") {
            EXPECT_EQ(submitted, drawn) << where;
        }
        EXPECT_GT(drawn, 0) << where;
    }
    return t;
}

}  // namespace

// Niessner & Loop's two-pass frame, the fused pass and one pass, with the default scene's displaced
// MonsterFrogs, in both schemes; and at tessellation 20 (226 patches a command at most: BigGuy's
// pass 1 alone lists more than 700).
TEST(IndirectDrawCli, EveryPatchModeVerifiesInBothSchemes) {
    EXPECT_GT(indirect_render("default --frames 3 --tess 4").occlusion, 0);
    EXPECT_GT(indirect_render("default --frames 1 --tess 2 --scheme osd --fused-pass --bound oobb").occlusion, 0);
    EXPECT_GT(indirect_render("default --frames 1 --tess 2 --scheme osd --cull frustum").submitted, 0);
    EXPECT_GT(indirect_render("bigguy --frames 2 --tess 20").occlusion, 0);
}

// Aggressive (Niessner & Loop §3.1, not conservative): the same frames as the flag path's, false
// culls included, and no pass 2 issued.
TEST(IndirectDrawCli, AggressiveMatchesTheFlagPath) {
    const IndirectTotals flags = indirect_render("default --frames 3 --tess 2 --aggressive", "flags", false);
    const IndirectTotals indirect = indirect_render("default --frames 3 --tess 2 --aggressive", "indirect", false);
    EXPECT_GT(flags.false_culls, 0);
    EXPECT_EQ(indirect.false_culls, flags.false_culls);
    EXPECT_EQ(indirect.occlusion, flags.occlusion);
    EXPECT_LT(indirect.submitted, flags.submitted);
}

// The object level and object occlusion: objects culled whole are never listed, the others'
// spans share one list and one multi-draw; CHC++'s and stop-and-wait's per-object draws compact
// each object as they draw it (two passes, and one pass with --cull frustum).
TEST(IndirectDrawCli, ObjectLevelAndObjectOcclusionVerify) {
    EXPECT_GT(indirect_render(indirect_city() + " --frames 2 --tess 2 --objects bvh+backface").objects_culled, 0);
    indirect_render(indirect_city() + " --frames 2 --tess 2 --scheme osd --objects bvh --object-occlusion chc++");
    indirect_render(indirect_city() +
                    " --frames 1 --tess 2 --cull frustum --objects frustum --object-occlusion stop-and-wait");
}

// 1e5 units out (each frame drawn near its camera): every test with the object level and CHC++,
// and the fused pass in the other scheme.
TEST(IndirectDrawCli, FarFromTheOriginVerifies) {
    const std::string file = write_file("indirect_far_1e5.json", indirect_far_scene(1e5));
    EXPECT_GT(indirect_render(file + " --frames 3 --tess 2 --objects bvh --object-occlusion chc++").occlusion, 0);
    EXPECT_GT(indirect_render(file + " --frames 3 --tess 2 --scheme osd --fused-pass").occlusion, 0);
}

// Bad values are one-line errors (exit 2), --compact's too (osd-table's own: osd_table_indirect_cli_test.cpp).
TEST(IndirectDrawCli, BadDrawValuesAreOneLineErrors) {
    expect_one_line_error(run("render default --frames 1 --draw indirekt"), "--draw");
    expect_one_line_error(run("render default --frames 1 --draw"), "--draw");
    expect_one_line_error(run("render default --frames 1 --draw flags --draw indirect"), "--draw");
    expect_one_line_error(run("view default --frames 1 --draw list"), "--draw");
    expect_one_line_error(run("view default --frames 1 --compact atomic"), "--compact");
    expect_one_line_error(run("view default --frames 1 --compact"), "--compact");
    expect_one_line_error(run("render default --frames 1 --compact"), "--compact");
}
