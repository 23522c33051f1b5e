// What a scene's motion reaches (check_scene_motion, patchcull/import/scene_file.h): objects moved by
// velocity x (time + time_offset), walk and orbit cameras, each refused at the first frame that
// goes beyond kMaxSceneCoordinate with one line naming the JSON path and the frame; and the
// scene reader's default object names, unique when one model stem stands for several models
// (two schemes, two files).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "patchcull/core/error.h"
#include "patchcull/import/scene_file.h"
#include "patchcull/import/scene_poser.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace patchcull;

namespace {

struct TempDir : test_files::TempDir {
    explicit TempDir(const std::string& name) : test_files::TempDir("patchcull_scene_motion", name) {}
};

constexpr double kSecondsPerFrame = 1.0 / 12.0;  // the CLI's (tools/render_support.h)

std::string test_name() { return ::testing::UnitTest::GetInstance()->current_test_info()->name(); }

Scene load_text(const TempDir& dir, const std::string& text, const std::string& file = "a.json") {
    const fs::path path = dir.path / file;
    test_files::write_file(path, text);
    return load_scene_file(path.string());
}

// The error check_scene_motion gives ("" when the motion stays within the limit). The one-frame
// reach (8192, measured from the origin here) keeps the numbers small; the scene limit is tested
// at the end.
std::string motion_error(const Scene& scene, int frames, double limit = kMaxSingleFrameReach) {
    try {
        check_scene_motion(scene, "a.json", frames, kSecondsPerFrame, limit);
    } catch (const Error& e) {
        std::string what = e.what();  // not const: returned by move
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        return what;
    }
    return "";
}

// A BigGuy standing at x = 0 and one object moving along +x; a camera path given as JSON.
std::string scene_text(const std::string& animation, const std::string& camera) {
    return R"({"objects": [{"model": "bigguy", "transform": {"height": 1}},
                           {"model": "monsterfrog", "transform": {"position": [0, 0, -2], "height": 1},
                            "animation": )" +
           animation + R"(}], "camera": )" + camera + "}";
}
const std::string kOrbit = R"({"orbit": {"distance": 4, "height": 1}})";

// The first frame f at which an object whose placed box ends at hi_x reaches beyond the limit
// moving at speed (t = f / 12 + offset).
int first_frame_beyond(double hi_x, double speed, double offset, double limit = kMaxSingleFrameReach) {
    for (int f = 0;; ++f)
        if (hi_x + speed * (f * kSecondsPerFrame + offset) > limit) return f;
}

}  // namespace

TEST(SceneMotion, AMovingObjectIsRefusedAtTheFirstFrameBeyondTheLimit) {
    TempDir dir(test_name());
    const Scene scene = load_text(dir, scene_text(R"({"velocity": [8000, 0, 0]})", kOrbit));
    // The MonsterFrog's placed box: its rest control points in world space.
    double hi_x = -1e30;
    for (const BezierPatch& p : scene.models.at(scene.instances[1].model).rest.patches)
        for (const Vec4& c : p.cp) hi_x = std::max(hi_x, double(cartesian(scene.instances[1].object_to_world * c).x));
    const int f = first_frame_beyond(hi_x, 8000, 0);
    ASSERT_GT(f, 1);
    EXPECT_EQ(motion_error(scene, f), "");  // frames 0 .. f - 1
    EXPECT_EQ(motion_error(scene, 1), "");
    const std::string e = motion_error(scene, f + 1);
    EXPECT_NE(e.find("a.json: objects[1].animation.velocity: the moving model ('monsterfrog#0') reaches x = "),
              std::string::npos)
        << e;
    EXPECT_NE(e.find(" at frame " + std::to_string(f) + " "), std::string::npos) << e;
    // Many frames: still the first frame beyond, not the last.
    EXPECT_NE(motion_error(scene, 1000).find(" at frame " + std::to_string(f) + " "), std::string::npos);
    // Moving back (-x): the same frame.
    const Scene back = load_text(dir, scene_text(R"({"velocity": [-8000, 0, 0]})", kOrbit), "b.json");
    EXPECT_NE(motion_error(back, 1000).find("reaches x = -"), std::string::npos) << motion_error(back, 1000);
}

TEST(SceneMotion, ATimeOffsetThatPlacesAnObjectBeyondTheLimitIsNamed) {
    TempDir dir(test_name());
    // Near 1e4 at frame 0: the loader checks the placement at rest; the time offset moves it.
    const Scene scene =
        load_text(dir, scene_text(R"({"deform": false, "time_offset": 1e6, "velocity": [0.01, 0, 0]})", kOrbit));
    const std::string e = motion_error(scene, 1);
    EXPECT_NE(e.find("a.json: objects[1].animation.time_offset: the moving model ('monsterfrog#0') reaches x = "),
              std::string::npos)
        << e;
    EXPECT_NE(e.find(" at frame 0 (time 0 s)"), std::string::npos) << e;
    // A time offset that keeps it within the limit (velocity x offset = 5000): accepted.
    const Scene near =
        load_text(dir, scene_text(R"({"time_offset": 5e5, "velocity": [0.01, 0, 0]})", kOrbit), "b.json");
    EXPECT_EQ(motion_error(near, 100), "");
    // A static object with any time offset does not move.
    const Scene still = load_text(dir, scene_text(R"({"time_offset": 1e6})", kOrbit), "c.json");
    EXPECT_EQ(motion_error(still, 1000), "");
}

TEST(SceneMotion, CamerasAreCheckedAtEveryFrame) {
    TempDir dir(test_name());
    // A walk of 700 units a frame from x = 0: 8400 at frame 12.
    const Scene walk = load_text(
        dir, scene_text("{}", R"({"walk": {"start": [0, 0.8, 4], "step": [700, 0, 0], "direction": [0, 0, -1]}})"));
    EXPECT_EQ(motion_error(walk, 12), "");
    std::string e = motion_error(walk, 13);
    EXPECT_NE(e.find("a.json: camera.walk.step: the camera's eye reaches x = 8400 at frame 12 (time 1 s)"),
              std::string::npos)
        << e;
    // Its target (eye + direction) beyond the limit while the eye is not.
    const Scene target = load_text(
        dir, scene_text("{}", R"({"walk": {"start": [8000, 0.8, 4], "step": [0, 0, 0], "direction": [8000, 0, 1]}})"),
        "b.json");
    e = motion_error(target, 1);
    EXPECT_NE(e.find("a.json: camera.walk.direction: the camera's target reaches x = 16000 at frame 0"),
              std::string::npos)
        << e;
    // An orbit whose distance reaches beyond the limit (accepted by the loader up to 2e11).
    const Scene orbit =
        load_text(dir, scene_text("{}", R"({"orbit": {"distance": 1e5, "start_degrees": 90}})"), "c.json");
    e = motion_error(orbit, 1);
    EXPECT_NE(e.find("a.json: camera.orbit.distance: the camera's eye reaches x = 100000 at frame 0"),
              std::string::npos)
        << e;
    // An orbit of radius 8000 around 0: every coordinate of its eye stays within 8000.
    const Scene turning =
        load_text(dir, scene_text("{}", R"({"orbit": {"distance": 8000, "degrees_per_frame": 45}})"), "d.json");
    EXPECT_EQ(motion_error(turning, 8), "");
    // A high orbit: the height is named.
    const Scene high = load_text(dir, scene_text("{}", R"({"orbit": {"distance": 4, "height": 9000}})"), "e.json");
    EXPECT_NE(motion_error(high, 1).find("camera.orbit.height: the camera's eye reaches y = 9000 at frame 0"),
              std::string::npos)
        << motion_error(high, 1);
}

TEST(SceneMotion, StillScenesPassForAnyFrameCount) {
    TempDir dir(test_name());
    const Scene scene = load_text(dir, scene_text(R"({"velocity": [0.5, 0, 0]})", kOrbit));
    EXPECT_EQ(motion_error(scene, 1000), "");
    EXPECT_EQ(motion_error(scene, 0), "");
    const Scene shipped = load_scene_file(std::string(PATCHCULL_SOURCE_DIR) + "/data/scenes/city_small.json");
    EXPECT_EQ(motion_error(shipped, 1000), "");
}

// Default names: "STEM#k" per model; where one stem stands for several models (file, scheme),
// the names say the scheme and (for different files) the model as the file writes it.
TEST(SceneFileNames, DefaultNamesAreUniqueAcrossSchemesAndPaths) {
    TempDir dir(test_name());
    // One model in both schemes: refused before ("duplicate object name 'bigguy#0'").
    Scene s = load_text(dir, R"({"objects": [{"model": "bigguy"}, {"model": "bigguy", "scheme": "osd"},
                                             {"model": "bigguy", "scheme": "acc", "transform": {"position": [2, 0, 0]}}],
                                  "camera": {"orbit": {"distance": 4}}})");
    ASSERT_EQ(s.instances.size(), 3u);
    EXPECT_EQ(s.models.size(), 2u);
    EXPECT_EQ(s.instances[0].name, "bigguy:acc#0");
    EXPECT_EQ(s.instances[1].name, "bigguy:osd#0");
    EXPECT_EQ(s.instances[2].name, "bigguy:acc#1");
    // One stem from two files: the names say the files as written.
    std::string cube;
    for (int i = 0; i < 8; ++i)
        cube += "v " + std::to_string(i & 1) + " " + std::to_string((i >> 1) & 1) + " " + std::to_string((i >> 2) & 1) +
                "\n";
    cube += "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
    for (const char* sub : {"a", "b"}) {
        fs::create_directories(dir.path / sub);
        std::ofstream(dir.path / sub / "cube.obj") << cube;
    }
    s = load_text(
        dir, R"({"objects": [{"model": "a/cube.obj"}, {"model": "b/cube.obj", "transform": {"position": [2, 0, 0]}},
                                       {"model": "./a/cube.obj", "transform": {"position": [4, 0, 0]}},
                                       {"model": "bigguy"}],
                            "camera": {"orbit": {"distance": 4}}})",
        "b.json");
    ASSERT_EQ(s.instances.size(), 4u);
    EXPECT_EQ(s.models.size(), 3u);
    EXPECT_EQ(s.instances[0].name, "a/cube.obj#0");
    EXPECT_EQ(s.instances[1].name, "b/cube.obj#0");
    EXPECT_EQ(s.instances[2].name, "a/cube.obj#1");  // the same file, spelt differently
    EXPECT_EQ(s.instances[3].name, "bigguy#0");      // a stem of one model keeps the short name
    // One model, one scheme: the short names, as before.
    s = load_text(dir,
                  R"({"objects": [{"model": "bigguy"}, {"model": "bigguy", "scheme": "acc"}, {"model": "monsterfrog"}],
                            "camera": {"orbit": {"distance": 4}}})",
                  "c.json");
    EXPECT_EQ(s.instances[0].name, "bigguy#0");
    EXPECT_EQ(s.instances[1].name, "bigguy#1");
    EXPECT_EQ(s.instances[2].name, "monsterfrog#0");
    // An explicit name equal to a default one is still a duplicate, reported as such.
    try {
        load_text(dir, R"({"objects": [{"model": "bigguy"}, {"model": "bigguy", "name": "bigguy#0"}],
                           "camera": {"orbit": {"distance": 4}}})",
                  "d.json");
        ADD_FAILURE() << "a duplicate name was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("objects[1].name: duplicate object name 'bigguy#0' (also objects[0])"),
                  std::string::npos)
            << e.what();
    }
}

// The scene limit (2^29) of `render`, which draws each frame near its camera: 1e6 units out is
// accepted, a scene that moves beyond 2^29 refused; the one-frame reach of the other commands,
// measured from the world's origin, refuses the same 1e6 scene and says why.
TEST(SceneMotion, TheSceneLimitAndTheOneFrameReach) {
    TempDir dir(test_name());
    const Scene far = load_text(dir, scene_text(R"({"time_offset": 1e6, "velocity": [1, 0, 0]})", kOrbit));
    EXPECT_EQ(motion_error(far, 200, kMaxSceneCoordinate), "");
    std::string e = motion_error(far, 1);
    EXPECT_NE(
        e.find(
            "objects[1].animation.time_offset: the moving model ('monsterfrog#0') reaches x = 999999 at frame "
            "0 (time 0 s); this command draws a scene in one float frame, at its first camera's grid point (0, 0, 0), "
            "and takes what lies within 8192 of it"),
        std::string::npos)
        << e;
    // 1e6 units per second from 5e8 (time offset 500 s): beyond 2^29 after 36.87 s.
    const Scene fast = load_text(dir, scene_text(R"({"time_offset": 500, "velocity": [1e6, 0, 0]})", kOrbit), "b.json");
    double hi_x = -1e30;
    for (const BezierPatch& p : fast.models.at(fast.instances[1].model).rest.patches)
        for (const Vec4& c : p.cp) hi_x = std::max(hi_x, double(cartesian(fast.instances[1].object_to_world * c).x));
    const int f = first_frame_beyond(hi_x, 1e6, 500, kMaxSceneCoordinate);
    EXPECT_EQ(f, 443);  // (2^29 - 5e8) / 1e6 s = 36.87 s: frame 443 (36.92 s)
    EXPECT_EQ(motion_error(fast, f, kMaxSceneCoordinate), "");
    e = motion_error(fast, f + 1, kMaxSceneCoordinate);
    EXPECT_NE(e.find("objects[1].animation.velocity: the moving model ('monsterfrog#0') reaches x = 5.36"),
              std::string::npos)
        << e;
    EXPECT_NE(e.find(" at frame 443 (time 36.9167 s); scenes take world coordinates up to 536870912 (2^29)"),
              std::string::npos)
        << e;
    // Static placements beyond the reach are named by their JSON path.
    const Scene placed = load_text(
        dir,
        R"({"objects": [{"model": "bigguy", "transform": {"position": [3e5, 0, 0]}}], "camera": {"orbit": {"distance": 4}}})",
        "c.json");
    EXPECT_EQ(motion_error(placed, 1, kMaxSceneCoordinate), "");
    EXPECT_NE(
        motion_error(placed, 1).find("a.json: objects[0].transform: the placed model ('bigguy#0') reaches x = 299"),
        std::string::npos)
        << motion_error(placed, 1);
}

// Commands that draw a run in one frame (demo, eval, view) move the scene's frame to their first
// camera's grid point: a scene 1e6 units out whose run stays near it is taken, in a frame at the
// camera (the cameras, cells and environment near 0), and a run that travels 9000 units from it
// is refused with the frame named.
TEST(SceneMotion, OneFrameCommandsDrawAtTheirFirstCamera) {
    TempDir dir(test_name());
    const std::string near = R"({"time_offset": 1e6, "velocity": [1, 0, 0]})";
    const std::string camera = R"({"orbit": {"target": [1e6, 0.5, -1], "distance": 4, "height": 1}})";
    Scene scene = load_text(dir,
                            R"({"objects": [{"model": "bigguy", "transform": {"position": [1e6, 0, 0], "height": 1}},
                           {"model": "monsterfrog", "transform": {"position": [0, 0, -2], "height": 1},
                            "animation": )" +
                                near + R"(}],
        "environment": [{"name": "wall", "box": {"min": [1e6, 0, -3], "max": [1000001, 1, -2.5]}}],
        "cells": [{"name": "c", "min": [999990, -1, -10], "max": [1000010, 5, 10]}],
        "camera": )" + camera + "}");
    place_scene_at_first_camera(scene, "a.json", 24, kSecondsPerFrame);
    EXPECT_EQ(scene.frame_origin.x, 1e6);
    EXPECT_EQ(scene.frame_origin.y, 0.0);
    const Camera first = scene.camera_path(1, 1.0f).front();
    EXPECT_LT(std::fabs(first.eye.x), 8.0f);
    EXPECT_EQ(first.target.x, 0.0f);
    EXPECT_EQ(scene.cells.at(0).box.min.x, -10.0f);  // rounded from the world's double, once
    EXPECT_EQ(scene.cells.at(0).box.max.x, 10.0f);
    ASSERT_FALSE(scene.occluder_vertices.empty());
    for (const Vec3& v : scene.occluder_vertices) EXPECT_LE(std::fabs(v.x), 1.0f);
    // A run that travels 9000 units from its frame.
    Scene fast = load_text(dir, scene_text(R"({"time_offset": 0, "velocity": [9000, 0, 0]})", kOrbit), "c.json");
    try {
        place_scene_at_first_camera(fast, "c.json", 24, kSecondsPerFrame);
        ADD_FAILURE() << "a run 9000 units from its frame was taken";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(
                      "c.json: objects[1].animation.velocity: the moving model ('monsterfrog#0') reaches x = "),
                  std::string::npos)
            << e.what();
        EXPECT_NE(
            std::string(e.what()).find("at frame 11 (time 0.916667 s); this command draws a scene in one float frame"),
            std::string::npos)
            << e.what();
    }
}

// Frames near the camera (scene_model.h): scene_frame_near's grid, instance_to_frame composed
// in double, rebase_scene rounding world coordinates into a frame once, camera paths in double.
TEST(SceneFrames, FrameOriginsAreTheWorldNearTheOriginAndAGridFarOut) {
    const DVec3 near = scene_frame_near({1000, -1024, 3});
    EXPECT_EQ(near.x, 0.0);
    EXPECT_EQ(near.y, 0.0);
    EXPECT_EQ(near.z, 0.0);
    const DVec3 far = scene_frame_near({1e6 + 7.9, 3, -1e5 - 8.2});
    EXPECT_EQ(far.x, 1e6);  // multiples of 16, on every axis
    EXPECT_EQ(far.y, 0.0);
    EXPECT_EQ(far.z, -1e5 - 16);
    const DVec3 eye{-4.2e8 + 0.3, 1025, 12345.678};
    const DVec3 o = scene_frame_near(eye);
    for (double d : {eye.x - o.x, eye.y - o.y, eye.z - o.z}) EXPECT_LE(std::fabs(d), kSceneFrameGrid / 2);
}

TEST(SceneFrames, InstancesAreComposedInDoubleAndRoundedOnce) {
    SceneInstance instance;
    instance.object_to_world.at(0, 3) = 0.25f;
    instance.origin = {1e6, 0, -3e5};
    instance.velocity = {8000, 0, 0.5f};
    instance.time_offset = 1000;
    // At t = 1 / 12: x = 0.25 + 1e6 + 8000 * 1000.0833..., in the frame at (9e6, 0, -3e5).
    const DVec3 frame{9e6, 0, -3e5};
    const Mat4 m = instance_to_frame(instance, 1.0f / 12.0f, frame);
    const double t = double(1.0f / 12.0f) + 1000.0;
    EXPECT_EQ(m.at(0, 3), static_cast<float>(0.25 + 1e6 + 8000.0 * t - 9e6));
    EXPECT_EQ(m.at(2, 3), static_cast<float>(0.5 * t));
    EXPECT_EQ(m.at(0, 0), 1.0f);
    // Into the world frame it is instance_to_world; a still instance at the origin keeps its matrix.
    const Mat4 w = instance_to_world(instance, 0);
    EXPECT_EQ(w.at(0, 3), static_cast<float>(0.25 + 1e6 + 8000.0 * 1000.0));
    SceneInstance still;
    still.object_to_world.at(1, 3) = 0.1f;
    EXPECT_EQ(instance_to_world(still, 5).at(1, 3), 0.1f);
}

TEST(SceneFrames, RebasedScenesPoseNearTheirFrame) {
    TempDir dir(test_name());
    // A BigGuy and a quad 1e6 out, an orbit camera around them.
    const Scene world =
        load_text(dir, R"({"objects": [{"model": "bigguy", "transform": {"position": [1000000.3, 0, 0], "height": 1},
                                                        "animation": {"deform": false, "velocity": [1, 0, 0]}}],
        "environment": [{"quad": [[999990.1, 0, -5], [999990.1, 0, 5], [1000010.1, 0, 5], [1000010.1, 0, -5]]}],
        "camera": {"orbit": {"target": [1000000.3, 0.5, 0], "distance": 3, "height": 0.5}}})");
    EXPECT_EQ(world.instances[0].origin.x, 1000000.0);
    EXPECT_EQ(world.camera.origin.x, 1000000.0);
    ASSERT_EQ(world.occluder_world.size(), world.occluder_vertices.size());
    const std::vector<WorldCamera> cameras = world.world_camera_path(3, 1.5f);
    const DVec3 origin = scene_frame_near(cameras[1].eye);
    Scene frame;
    frame.models = world.models;
    rebase_scene(world, origin, frame);
    EXPECT_EQ(frame.frame_origin.x, origin.x);
    // Occluders: world coordinates minus the origin, rounded once (near 0).
    for (std::size_t i = 0; i < frame.occluder_vertices.size(); ++i) {
        EXPECT_EQ(frame.occluder_vertices[i].x, static_cast<float>(world.occluder_world[i].x - origin.x));
        EXPECT_LE(std::fabs(frame.occluder_vertices[i].x), 20.0f);
    }
    // Cameras: the world camera moved into the frame; its eye within 8 of 0.
    const std::vector<Camera> local = frame.camera_path(3, 1.5f);
    const Camera expected = cameras[1].local(origin);
    EXPECT_NEAR(local[1].eye.x, expected.eye.x, 1e-5);
    EXPECT_NEAR(local[1].eye.z, expected.eye.z, 1e-5);
    EXPECT_LE(std::fabs(local[1].eye.x), 8.0f);
    // A frame the path's origin is not: composed in double (world_camera_path, then local).
    Scene moved;
    rebase_scene(world, {origin.x + 32, origin.y, origin.z}, moved);
    const Camera there = moved.camera_path(3, 1.5f)[2];
    const Camera expected_there = cameras[2].local({origin.x + 32, origin.y, origin.z});
    EXPECT_EQ(there.eye.x, expected_there.eye.x);
    EXPECT_EQ(there.target.z, expected_there.target.z);
    // Patches: posed near 0, where the world's patches are, to float precision at their size.
    ScenePoser world_poser(world), frame_poser(frame);
    const std::vector<BezierPatch> far = world_poser.pose(1.0f / 12.0f);
    const std::vector<BezierPatch>& near = frame_poser.pose(1.0f / 12.0f);
    ASSERT_EQ(far.size(), near.size());
    const double x = 1000000.3 + 1.0 / 12.0 - origin.x;
    float lo = 1e30f, hi = -1e30f;
    for (const BezierPatch& p : near)
        for (const Vec4& c : p.cp) lo = std::min(lo, c.x), hi = std::max(hi, c.x);
    EXPECT_LT(lo, float(x));
    EXPECT_GT(hi, float(x));
    EXPECT_LT(hi - lo, 2.0f);
    for (std::size_t p = 0; p < near.size(); p += 97)
        for (int k = 0; k < 16; ++k) EXPECT_NEAR(double(near[p].cp[k].x) + origin.x, double(far[p].cp[k].x), 0.07);
}
