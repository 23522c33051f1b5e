// What a scene's motion reaches (check_scene_motion, patchcull/scene_file.h): objects moved by
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

#include <unistd.h>

#include "patchcull/error.h"
#include "patchcull/scene_file.h"

namespace fs = std::filesystem;
using namespace patchcull;

namespace {

constexpr double kSecondsPerFrame = 1.0 / 12.0;  // the CLI's (tools/render_support.h)

struct TempDir {
    fs::path path;
    explicit TempDir(const std::string& name)
        : path(fs::temp_directory_path() / ("patchcull_scene_motion_" + name + "_" + std::to_string(::getpid()))) {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
};

std::string test_name() { return ::testing::UnitTest::GetInstance()->current_test_info()->name(); }

Scene load_text(const TempDir& dir, const std::string& text, const std::string& file = "a.json") {
    const fs::path path = dir.path / file;
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << text;
    return load_scene_file(path.string());
}

// The error check_scene_motion gives ("" when the motion stays within the limit).
std::string motion_error(const Scene& scene, int frames) {
    try {
        check_scene_motion(scene, "a.json", frames, kSecondsPerFrame);
    } catch (const Error& e) {
        const std::string what = e.what();
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
int first_frame_beyond(double hi_x, double speed, double offset) {
    for (int f = 0;; ++f)
        if (hi_x + speed * (f * kSecondsPerFrame + offset) > kMaxSceneCoordinate) return f;
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
    const Scene scene = load_text(dir, scene_text(R"({"deform": false, "time_offset": 1e6, "velocity": [0.01, 0, 0]})", kOrbit));
    const std::string e = motion_error(scene, 1);
    EXPECT_NE(e.find("a.json: objects[1].animation.time_offset: the moving model ('monsterfrog#0') reaches x = "),
              std::string::npos)
        << e;
    EXPECT_NE(e.find(" at frame 0 (time 0 s)"), std::string::npos) << e;
    // A time offset that keeps it within the limit (velocity x offset = 5000): accepted.
    const Scene near = load_text(dir, scene_text(R"({"time_offset": 5e5, "velocity": [0.01, 0, 0]})", kOrbit), "b.json");
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
    const Scene orbit = load_text(dir, scene_text("{}", R"({"orbit": {"distance": 1e5, "start_degrees": 90}})"), "c.json");
    e = motion_error(orbit, 1);
    EXPECT_NE(e.find("a.json: camera.orbit.distance: the camera's eye reaches x = 100000 at frame 0"), std::string::npos)
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
        cube += "v " + std::to_string(i & 1) + " " + std::to_string((i >> 1) & 1) + " " + std::to_string((i >> 2) & 1) + "\n";
    cube += "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
    for (const char* sub : {"a", "b"}) {
        fs::create_directories(dir.path / sub);
        std::ofstream(dir.path / sub / "cube.obj") << cube;
    }
    s = load_text(dir, R"({"objects": [{"model": "a/cube.obj"}, {"model": "b/cube.obj", "transform": {"position": [2, 0, 0]}},
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
    s = load_text(dir, R"({"objects": [{"model": "bigguy"}, {"model": "bigguy", "scheme": "acc"}, {"model": "monsterfrog"}],
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
