// Scenes far from the origin, drawn camera-relative (default_scene.h's rebase_scene): `render
// SCENE --verify` reports 0 false culls for a chase at 8000 units per second (a BigGuy and a
// displaced MonsterFrog, both deforming, a walk camera following them to 1.3e5 units in 200
// frames) and for characters, a ground and a wall placed 1e5 and 1e6 units out by their time
// offset, under every cull mode and back-patch method, the fused pass, GPU posing, displaced
// bounds, every --objects method and the --object-occlusion methods a scene without cells has.
// Drawn in float world coordinates instead (before the frames), the chase had its first false
// cull at frame 35 and the 1e5 and 1e6 scenes 1-20 in 3 frames (all, occlusion, ncone). Tiny
// sizes and tessellation 2: llvmpipe renders every frame twice.
#include <gtest/gtest.h>

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
  {"model": "bigguy", "transform": {"yaw_degrees": 200, "height": 1}, )" + animated + R"(},
  {"model": "bigguy", "transform": {"position": [0.9, 0, -1.3], "yaw_degrees": 160, "height": 1},
   "animation": {"deform": false, "time_offset": )" + x + R"(, "velocity": [1, 0, 0]}},
  {"model": "bigguy", "transform": {"position": [-0.8, 0, -2.2], "yaw_degrees": 180, "height": 1}, )" + animated + R"(},
  {"model": "monsterfrog", "transform": {"position": [0.2, 0, -3.2], "height": 0.7}, )" + animated +
           R"(, "displaced": true},
  {"model": "bigguy", "transform": {"position": [7, 0, 4], "height": 1},
   "animation": {"deform": false, "time_offset": )" + x + R"(, "velocity": [1, 0, 0]}}],
 "environment": [
  {"name": "ground", "quad": [[)" + at(-6) + R"(, -0.002, -8], [)" + at(-6) + R"(, -0.002, 4], [)" + at(6) +
           R"(, -0.002, 4], [)" + at(6) + R"(, -0.002, -8]], "one_sided": true},
  {"name": "wall", "box": {"min": [)" + at(1.4) + R"(, 0, -2.6], "max": [)" + at(1.6) + R"(, 1.1, -0.8]}}],
 "camera": {"orbit": {"target": [)" + x + R"(, 0.5, -1.2], "distance": 4, "height": 0.8, "start_degrees": 20,
            "degrees_per_frame": 25}, "z_near": 0.05, "z_far": 40}}
)";
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
        EXPECT_EQ(f["false_culls"], 0) << what << ", frame " << f["frame"] << ": " << f.value("false_culled_patches", nlohmann::json()).dump();
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
// methods (portals need cells, which stay within 8192: kMaxFloatWorldCoordinate).
TEST(FarSceneCli, ObjectsPlacedFarByTheirTimeOffsetVerify) {
    for (double d : {1e5, 1e6}) {
        const std::string file = write_file("far_" + std::to_string(static_cast<long long>(d)) + ".json", far_scene(d));
        EXPECT_GT(verified(file, "--cull frustum", 3).frustum, 0u);
        EXPECT_GT(verified(file, "--cull backpatch --backpatch ncone --objects bvh", 3).backpatch, 0u);
        EXPECT_GT(verified(file, "--cull backpatch --backpatch ptp --pose gpu", 3).backpatch, 0u);
        EXPECT_GT(verified(file, "--cull occlusion --objects bvh+backface --object-occlusion horizon", 3).occlusion, 0u);
        const Counts all = verified(file, "--objects frustum --object-occlusion stop-and-wait", 3);
        EXPECT_GT(all.objects_frustum, 0u);
        EXPECT_GT(all.occlusion, 0u);
        EXPECT_GT(all.backpatch, 0u);
        EXPECT_GT(verified(file, "--fused-pass --backpatch ncone --objects bvh --object-occlusion batched", 3).occlusion, 0u);
        EXPECT_GT(verified(file, "--displace procedural --displace-scale 0.03 --bound oobb --objects frustum --object-occlusion chc", 3).occlusion, 0u);
        verified(file, "--cull auto --objects bvh", 3);
        EXPECT_GT(verified(file, "--frustum aabb --objects bvh+backface --object-occlusion chc++", 3).occlusion, 0u);
    }
}
