// Scenes far from the origin, drawn camera-relative (scene_model.h's rebase_scene): `render
// SCENE --verify` reports 0 false culls for a chase at 8000 units per second (a BigGuy and a
// displaced MonsterFrog, both deforming, a walk camera following them to 1.3e5 units in 200
// frames) and for characters, a ground and a wall placed 1e5 and 1e6 units out by their time
// offset, under every cull mode and back-patch method, the fused pass, GPU posing, displaced
// bounds, every --objects method and every --object-occlusion method (portals in two rooms moved
// out with their cells and portal).
// Drawn in float world coordinates instead (before the frames), the chase had its first false
// cull at frame 35 and the 1e5 and 1e6 scenes 1-20 in 3 frames (all, occlusion, ncone). Tiny
// sizes and tessellation 2: llvmpipe renders every frame twice.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

std::string test_scene(const char* name) { return std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/scenes/" + name; }

// Three BigGuys (two deforming) and a displaced MonsterFrog, moving at 1 unit per second with a
// time offset of d seconds (so at x = d + t), among a ground quad and a wall box placed at d,
// seen by an orbit camera around them (25 degrees a frame); a fourth BigGuy out of view.
std::string far_scene(double d) {
    const std::string x = std::to_string(static_cast<long long>(d));
    auto at = [&](double dx) { return std::to_string(d + dx); };
    const std::string animated = R"("animation": {"time_offset": )" + x + R"(, "velocity": [1, 0, 0]})";
    return R"({"name": "far", "displacement": {"map": "procedural", "scale": 0.03, "size": 64},
 "objects": [
  {"model": "bigguy", "transform": {"yaw_degrees": 200, "height": 1}, )" +
           animated + R"(},
  {"model": "bigguy", "transform": {"position": [0.9, 0, -1.3], "yaw_degrees": 160, "height": 1},
   "animation": {"deform": false, "time_offset": )" +
           x + R"(, "velocity": [1, 0, 0]}},
  {"model": "bigguy", "transform": {"position": [-0.8, 0, -2.2], "yaw_degrees": 180, "height": 1}, )" +
           animated + R"(},
  {"model": "monsterfrog", "transform": {"position": [0.2, 0, -3.2], "height": 0.7}, )" +
           animated +
           R"(, "displaced": true},
  {"model": "bigguy", "transform": {"position": [7, 0, 4], "height": 1},
   "animation": {"deform": false, "time_offset": )" +
           x + R"(, "velocity": [1, 0, 0]}}],
 "environment": [
  {"name": "ground", "quad": [[)" +
           at(-6) + R"(, -0.002, -8], [)" + at(-6) + R"(, -0.002, 4], [)" + at(6) + R"(, -0.002, 4], [)" + at(6) +
           R"(, -0.002, -8]], "one_sided": true},
  {"name": "wall", "box": {"min": [)" +
           at(1.4) + R"(, 0, -2.6], "max": [)" + at(1.6) + R"(, 1.1, -0.8]}}],
 "camera": {"orbit": {"target": [)" +
           x + R"(, 0.5, -1.2], "distance": 4, "height": 0.8, "start_degrees": 20,
            "degrees_per_frame": 25}, "z_near": 0.05, "z_far": 40}}
)";
}

// tests/data/scenes/two_rooms.json moved d units along x: every position, box corner, cell and
// portal corner and the camera's start.
std::string two_rooms_at(double d) {
    std::ifstream in(test_scene("two_rooms.json"));
    nlohmann::json scene = nlohmann::json::parse(in);
    auto shift = [d](nlohmann::json& point) { point[0] = point[0].get<double>() + d; };
    for (auto& o : scene["objects"])
        if (o["transform"].contains("position")) shift(o["transform"]["position"]);
    for (auto& e : scene["environment"]) {
        shift(e["box"]["min"]);
        shift(e["box"]["max"]);
    }
    for (auto& c : scene["cells"]) {
        shift(c["min"]);
        shift(c["max"]);
    }
    for (auto& p : scene["portals"])
        for (auto& corner : p["corners"]) shift(corner);
    shift(scene["camera"]["walk"]["start"]);
    return scene.dump();
}

struct Counts {
    std::size_t frustum = 0, backpatch = 0, occlusion = 0, objects_frustum = 0;
};

// Runs `render FILE ARGS --verify --json` and checks: exit 0, 0 false culls in every frame,
// something visible in every frame. Returns the culled counts over the frames.
Counts verified(const std::string& file, const std::string& args, std::size_t frames) {
    Counts c;
    const std::string what = file.substr(file.rfind('/') + 1) + " " + args;
    const CliRun r = run("render " + file + " --size 64x48 --tess 2 --frames " + std::to_string(frames) + " " + args +
                         " --verify --json");
    EXPECT_EQ(r.status, 0) << what << ": " << r.err << r.out.substr(0, 1000);
    if (r.out.empty()) return c;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["false_culls"], 0) << what;
    EXPECT_EQ(j["frames"].size(), frames) << what;
    for (const nlohmann::json& f : j["frames"]) {
        EXPECT_EQ(f["false_culls"], 0) << what << ", frame " << f["frame"] << ": "
                                       << f.value("false_culled_patches", nlohmann::json()).dump();
        EXPECT_GT(f["visible"].get<std::size_t>(), 0u) << what << ", frame " << f["frame"];
        c.backpatch += f["backpatch_culled"].get<std::size_t>();
        c.occlusion += f["occlusion_culled"].get<std::size_t>();
        c.frustum += f["frustum_culled"].get<std::size_t>();
        c.objects_frustum += f["objects"]["frustum_culled"].get<std::size_t>();
    }
    return c;
}

}  // namespace

// The chase: 8000 units per second for 200 frames (16.7 s, x to 1.33e5), the camera keeping
// them in view, every test of `all` and the object level (made again in every frame's frame);
// the occlusion test culls the frog behind the BigGuy every frame.
TEST(FarSceneCli, ChaseAt8000UnitsPerSecondVerifies) {
    const Counts all = verified(test_scene("chase_8000.json"), "--objects bvh+backface", 200);
    EXPECT_GT(all.occlusion, 200u);
    EXPECT_GT(all.backpatch, 200u);
}

// Characters, ground and wall at 1e5 and 1e6: every cull mode and back-patch method, the fused pass, GPU
// posing, displaced bounds, every object-level method and the query and horizon occlusion
// methods but portals (the scene has no cells: the next test).
TEST(FarSceneCli, ObjectsPlacedFarByTheirTimeOffsetVerify) {
    for (double d : {1e5, 1e6}) {
        const std::string file = write_file("far_" + std::to_string(static_cast<long long>(d)) + ".json", far_scene(d));
        EXPECT_GT(verified(file, "--cull frustum", 3).frustum, 0u);
        EXPECT_GT(verified(file, "--cull backpatch --backpatch ncone --objects bvh", 3).backpatch, 0u);
        EXPECT_GT(verified(file, "--cull backpatch --backpatch ptp --pose gpu", 3).backpatch, 0u);
        EXPECT_GT(verified(file, "--cull occlusion --objects bvh+backface --object-occlusion horizon", 3).occlusion,
                  0u);
        const Counts all = verified(file, "--objects frustum --object-occlusion stop-and-wait", 3);
        EXPECT_GT(all.objects_frustum, 0u);
        EXPECT_GT(all.occlusion, 0u);
        EXPECT_GT(all.backpatch, 0u);
        EXPECT_GT(
            verified(file, "--fused-pass --backpatch ncone --objects bvh --object-occlusion batched", 3).occlusion, 0u);
        EXPECT_GT(
            verified(
                file,
                "--displace procedural --displace-scale 0.03 --bound oobb --objects frustum --object-occlusion chc", 3)
                .occlusion,
            0u);
        verified(file, "--cull auto --objects bvh", 3);
        EXPECT_GT(verified(file, "--frustum aabb --objects bvh+backface --object-occlusion chc++", 3).occlusion, 0u);
    }
}

// Portals 1e5 and 1e6 units out: the cells and the portal are world positions in double, rounded
// into each frame's floats with the rest; the walk crosses the door, and portal culling hides
// objects (of the room behind the wall) in some frame.
TEST(FarSceneCli, PortalsFarOutVerify) {
    for (double d : {1e5, 1e6}) {
        const std::string file =
            write_file("two_rooms_" + std::to_string(static_cast<long long>(d)) + ".json", two_rooms_at(d));
        const CliRun r =
            run("render " + file +
                " --size 64x48 --tess 2 --frames 6 --objects frustum --object-occlusion portals --verify --json");
        ASSERT_EQ(r.status, 0) << r.err;
        const nlohmann::json j = nlohmann::json::parse(r.out);
        EXPECT_EQ(j["false_culls"], 0) << d;
        std::size_t hidden = 0;
        for (const nlohmann::json& f : j["frames"]) {
            EXPECT_TRUE(f["objects"]["occlusion"]["eye_in_cell"].get<bool>()) << d << ", frame " << f["frame"];
            hidden += f["objects"]["occlusion"]["objects_culled"].get<std::size_t>();
        }
        EXPECT_GT(hidden, 0u) << d << ": " << r.out.substr(0, 2000);
    }
}

// The commands that draw a run in one float frame (eval, demo, view) take a scene 1e6 units out
// in a frame at their first camera: `eval scene` with portals and `eval fused` (in reversed-Z
// with an infinite far plane) verify against the unculled id buffer; a run that walks 9000 units
// from its first camera is refused with one line naming the step and the frame. `eval displaced`
// decides the same in reversed-Z as in zero-to-one.
TEST(FarSceneCli, OneFrameCommandsTakeFarScenes) {
    const std::string file = write_file("two_rooms_eval_1e6.json", two_rooms_at(1e6));
    CliRun r = run("eval scene " + file + " --frames 3 --size 64x48 --tess 2 --methods portals --json");
    ASSERT_EQ(r.status, 0) << r.err;
    nlohmann::json j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["methods"].size(), 2u);
    for (const nlohmann::json& m : j["methods"]) EXPECT_EQ(m["false_culls"], 0) << m.dump();
    EXPECT_GT(j["methods"][1]["objects_culled"].get<double>(), 0.0) << r.out;
    r = run("eval fused " + file + " --frames 2 --size 64x48 --repeats 1 --clip-depth reversed-infinite --json");
    ASSERT_EQ(r.status, 0) << r.err;
    j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["clip_depth"], "reversed-infinite");
    EXPECT_EQ(j["false_culls"], 0);
    EXPECT_GT(j["culled"]["occlusion"].get<double>(), 0.0);

    nlohmann::json away = nlohmann::json::parse(two_rooms_at(1e6));
    away["camera"]["walk"]["step"] = {0, 0, -1000};
    const std::string far_walk = write_file("two_rooms_walk_away.json", away.dump());
    r = run("eval scene " + far_walk + " --frames 12 --size 64x48 --methods portals --json");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("camera.walk.step: the camera's eye reaches z = "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("at frame 9 (time 0.75 s); this command draws a scene in one float frame"), std::string::npos)
        << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;

    const std::string bigguy = std::string(PATCHCULL_SOURCE_DIR) + "/data/models/bigguy.obj";
    nlohmann::json rows[2];
    for (int k = 0; k < 2; ++k) {
        r = run("eval displaced " + bigguy + " --views 2 --size 64x48 --tess 2 --json --clip-depth " +
                (k == 0 ? "zero-to-one" : "reversed"));
        ASSERT_EQ(r.status, 0) << r.err;
        rows[k] = nlohmann::json::parse(r.out)["rows"];
    }
    ASSERT_EQ(rows[0].size(), rows[1].size());
    for (std::size_t i = 0; i < rows[0].size(); ++i) {
        EXPECT_EQ(rows[1][i]["false_culls"], 0);
        EXPECT_EQ(rows[1][i]["pipeline_false_culls"], 0);
        EXPECT_GT(rows[1][i]["cull_rate"].get<double>(), 0.0);
        EXPECT_NEAR(rows[1][i]["cull_rate"].get<double>(), rows[0][i]["cull_rate"].get<double>(), 0.01);
    }
}
