// Scene files (patchcull/import/scene_file.h): the shipped files (default.json is the built-in default
// scene, bit for bit), every error message kind with its file and JSON path, relative paths,
// models loaded once per (file, scheme), OBJ environment objects, far-from-origin and
// degenerate inputs, and a deterministic mutation run (a few hundred mutants of a valid file
// load or throw Error with one printable line, never crash).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_file.h"
#include "patchcull/import/scene_poser.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace patchcull;

namespace {

struct TempDir : test_files::TempDir {
    explicit TempDir(const std::string& name) : test_files::TempDir("patchcull_scene_file", name) {}
};
using test_files::write_file;

const fs::path kScenes = fs::path(PATCHCULL_SOURCE_DIR) / "data" / "scenes";

// A unit cube as a closed, outward quad mesh, offset by `at`.
std::string cube_obj(double at = 0, double size = 1) {
    std::string text;
    for (int i = 0; i < 8; ++i) {
        char line[160];
        std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", at + ((i & 1) ? size : 0), at + ((i & 2) ? size : 0),
                      at + ((i & 4) ? size : 0));
        text += line;
    }
    // 1-based corners, counter-clockwise seen from outside (-x, +x, -y, +y, -z, +z).
    text += "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
    return text;
}

// A small valid scene using the cube (models and environment), the teapot, every section.
std::string valid_scene() {
    return R"({
  "name": "small",
  "displacement": {"map": "procedural", "scale": 0.02, "size": 64},
  "animation": {"period_seconds": 3},
  "objects": [
    {"name": "a", "model": "cube.obj", "transform": {"position": [0, 0, 0], "height": 1}, "displaced": true},
    {"name": "b", "model": "cube.obj", "scheme": "acc", "transform": {"position": [2, 0, 0], "yaw_degrees": 30, "scale": 0.5},
     "animation": {"deform": false, "time_offset": 0.5, "velocity": [0.1, 0, 0]}},
    {"name": "t", "model": "teapot", "transform": [1, 0, 0, -2, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}
  ],
  "environment": [
    {"name": "ground", "quad": [[-5, 0, -5], [-5, 0, 5], [5, 0, 5], [5, 0, -5]], "one_sided": true},
    {"name": "box", "box": {"min": [3, 0, 3], "max": [4, 1, 4]}},
    {"name": "mesh", "obj": "cube.obj", "transform": {"position": [-3, 0, 3], "scale": 2}}
  ],
  "camera": {"orbit": {"target": [0, 0.5, 0], "distance": 6, "height": 1}, "fovy_degrees": 50, "z_near": 0.1, "z_far": 40},
  "cells": [
    {"name": "left", "min": [-5, 0, -5], "max": [0, 3, 5], "objects": ["a", "t"], "environment": ["mesh"]},
    {"name": "right", "min": [0, 0, -5], "max": [5, 3, 5], "objects": ["b"], "environment": ["box"]}
  ],
  "portals": [{"cells": ["left", "right"], "corners": [[0, 0, -1], [0, 0, 1], [0, 2, 1], [0, 2, -1]]}]
}
)";
}

// Loads text as dir/a.json and returns the error message ("" when it loads).
std::string load_error(const fs::path& dir, const std::string& text, const std::string& file = "a.json") {
    const fs::path path = dir / file;
    write_file(path, text);
    try {
        load_scene_file(path.string());
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// A valid scene with one replacement (which must apply).
std::string with(std::string text, const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

class SceneFileErrors : public ::testing::Test {
protected:
    void SetUp() override {
        temp_ = std::make_unique<TempDir>(::testing::UnitTest::GetInstance()->current_test_info()->name());
        dir_ = temp_->path;
        write_file(dir_ / "cube.obj", cube_obj());
        ASSERT_EQ(load_error(dir_, valid_scene()), "");
    }
    // The message of the mutated valid scene: exactly "dir/a.json: " + expected.
    void expect(const std::string& text, const std::string& expected) {
        const std::string message = load_error(dir_, text);
        EXPECT_EQ(message, (dir_ / "a.json").string() + ": " + expected);
        EXPECT_TRUE(is_printable_line(message)) << message;
    }
    // The same, where the message goes on with a computed number: the part up to it.
    void expect_prefix(const std::string& text, const std::string& expected) {
        const std::string message = load_error(dir_, text);
        const std::string prefix = (dir_ / "a.json").string() + ": " + expected;
        EXPECT_EQ(message.substr(0, prefix.size()), prefix) << message;
        EXPECT_TRUE(is_printable_line(message)) << message;
    }
    std::unique_ptr<TempDir> temp_;
    fs::path dir_;
};

Bounds bounds_of(const std::vector<Vec3>& points) { return compute_bounds(points); }

}  // namespace

TEST(SceneFile, DefaultJsonIsTheDefaultScene) {
    const Scene file = load_scene_file((kScenes / "default.json").string());
    const Scene built = make_default_scene();
    EXPECT_EQ(file.name, "default");
    ASSERT_EQ(file.models.size(), built.models.size());
    for (std::size_t m = 0; m < file.models.size(); ++m)
        EXPECT_EQ(file.models[m].rest.patches.size(), built.models[m].rest.patches.size());
    EXPECT_EQ(file.patch_count(), built.patch_count());
    ASSERT_EQ(file.instances.size(), built.instances.size());
    for (std::size_t i = 0; i < file.instances.size(); ++i) {
        const SceneInstance &a = file.instances[i], &b = built.instances[i];
        EXPECT_EQ(a.name, b.name);
        EXPECT_EQ(a.model, b.model);
        for (int k = 0; k < 16; ++k)
            EXPECT_EQ(a.object_to_world.m[k], b.object_to_world.m[k]) << a.name << " element " << k;
        EXPECT_EQ(a.time_offset, b.time_offset) << a.name;
        EXPECT_EQ(a.displaced, b.displaced);
        EXPECT_EQ(a.deforms, b.deforms);
        EXPECT_EQ(length(a.velocity), 0.0f);
    }
    ASSERT_EQ(file.occluder_vertices.size(), built.occluder_vertices.size());
    for (std::size_t v = 0; v < file.occluder_vertices.size(); ++v) {
        EXPECT_EQ(file.occluder_vertices[v].x, built.occluder_vertices[v].x) << v;
        EXPECT_EQ(file.occluder_vertices[v].y, built.occluder_vertices[v].y) << v;
        EXPECT_EQ(file.occluder_vertices[v].z, built.occluder_vertices[v].z) << v;
    }
    EXPECT_EQ(file.occluder_indices, built.occluder_indices);
    ASSERT_EQ(file.environment.size(), built.environment.size());
    for (std::size_t e = 0; e < file.environment.size(); ++e) {
        EXPECT_EQ(file.environment[e].name, built.environment[e].name);
        EXPECT_EQ(file.environment[e].first_triangle, built.environment[e].first_triangle);
        EXPECT_EQ(file.environment[e].triangle_count, built.environment[e].triangle_count);
        EXPECT_EQ(file.environment[e].one_sided, built.environment[e].one_sided);
    }
    const CameraPath &a = file.camera, &b = built.camera;
    EXPECT_FALSE(a.walk);
    EXPECT_EQ(a.target.x, b.target.x);
    EXPECT_EQ(a.target.y, b.target.y);
    EXPECT_EQ(a.target.z, b.target.z);
    EXPECT_EQ(a.distance, b.distance);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.start_degrees, b.start_degrees);
    EXPECT_EQ(a.degrees_per_frame, b.degrees_per_frame);
    EXPECT_EQ(a.fovy_radians, b.fovy_radians);
    EXPECT_EQ(a.z_near, b.z_near);
    EXPECT_EQ(a.z_far, b.z_far);
    EXPECT_EQ(file.displacement_name, "procedural");
    EXPECT_EQ(file.displacement.width, built.displacement.width);
    EXPECT_EQ(file.displacement.scale, built.displacement.scale);
    EXPECT_EQ(file.displacement.texels, built.displacement.texels);
    // The same poses.
    ScenePoser pa(file), pb(built);
    const std::vector<BezierPatch> x = pa.pose(0.7f);
    const std::vector<BezierPatch>& y = pb.pose(0.7f);
    ASSERT_EQ(x.size(), y.size());
    for (std::size_t p = 0; p < x.size(); p += 31) EXPECT_EQ(x[p].cp[5].x, y[p].cp[5].x);
}

// Bounds of the environment objects whose names start with one of the prefixes.
std::vector<Bounds> solids(const Scene& scene, std::initializer_list<const char*> prefixes) {
    std::vector<Bounds> out;
    for (const EnvironmentObject& o : scene.environment) {
        if (std::none_of(prefixes.begin(), prefixes.end(), [&](const char* p) { return o.name.rfind(p, 0) == 0; }))
            continue;
        std::vector<Vec3> points;
        for (std::uint32_t t = o.first_triangle; t < o.first_triangle + o.triangle_count; ++t)
            for (int k = 0; k < 3; ++k) points.push_back(scene.occluder_vertices[scene.occluder_indices[3 * t + k]]);
        out.push_back(bounds_of(points));
    }
    return out;
}

// Over the CLI's 60 frames at 1/12 s (every third) no character's posed bounds overlap a solid,
// and the eye is inside no character and no solid.
void check_clear(const Scene& scene, const std::vector<Bounds>& solid) {
    ScenePoser poser(scene);
    const std::vector<Camera> cameras = scene.camera_path(60, 16.0f / 9.0f);
    auto inside = [](Vec3 e, const Bounds& b) {
        return e.x > b.min.x && e.x < b.max.x && e.y > b.min.y && e.y < b.max.y && e.z > b.min.z && e.z < b.max.z;
    };
    for (int f = 0; f < 60; f += 3) {
        const std::vector<BezierPatch>& patches = poser.pose(f / 12.0f);
        const Vec3 e = cameras[static_cast<std::size_t>(f)].eye;
        for (const Bounds& s : solid) EXPECT_FALSE(inside(e, s)) << "eye in a solid at frame " << f;
        std::size_t first = 0;
        for (const SceneInstance& instance : scene.instances) {
            std::vector<Vec3> points;
            const std::size_t n = scene.models[instance.model].rest.patches.size();
            for (std::size_t p = first; p < first + n; ++p)
                for (const Vec4& c : patches[p].cp) points.push_back(cartesian(c));
            first += n;
            const Bounds b = bounds_of(points);
            for (const Bounds& s : solid)
                EXPECT_FALSE(b.min.x < s.max.x && s.min.x < b.max.x && b.min.y < s.max.y && s.min.y < b.max.y &&
                             b.min.z < s.max.z && s.min.z < b.max.z)
                    << instance.name << " frame " << f;
            EXPECT_FALSE(inside(e, b)) << "eye inside " << instance.name << " at frame " << f;
        }
    }
}

TEST(SceneFile, ShippedCityAndBuildingFiles) {
    const Scene city = load_scene_file((kScenes / "city_small.json").string());
    EXPECT_EQ(city.instances.size(), 20u);
    EXPECT_EQ(city.models.size(), 2u);  // BigGuy and MonsterFrog, each loaded once
    EXPECT_TRUE(city.camera.walk);
    for (const EnvironmentObject& o : city.environment) EXPECT_TRUE(o.one_sided) << o.name;
    int walking = 0, rigid = 0;
    for (const SceneInstance& i : city.instances) walking += length(i.velocity) > 0, rigid += !i.deforms;
    EXPECT_GT(walking, 0);
    EXPECT_GT(rigid, 0);
    const std::vector<Bounds> buildings = solids(city, {"building#"});
    ASSERT_EQ(buildings.size(), 4u);
    check_clear(city, buildings);

    const Scene building = load_scene_file((kScenes / "building.json").string());
    ASSERT_EQ(building.cells.size(), 3u);
    ASSERT_EQ(building.portals.size(), 2u);
    EXPECT_EQ(building.cells[0].name, "hall");
    std::size_t listed = 0;
    for (const SceneCell& c : building.cells) listed += c.instances.size();
    EXPECT_EQ(listed, building.instances.size());
    for (const ScenePortal& p : building.portals) {
        EXPECT_NE(p.cell_a, p.cell_b);
        Vec3 centre{};
        for (const Vec3& c : p.corners) centre += c * 0.25f;
        const Vec3 n = cross(p.corners[1] - p.corners[0], p.corners[2] - p.corners[0]);
        EXPECT_GT(dot(n, building.cells[p.cell_a].box.center() - centre), 0.0f);
    }
    // Walls, posts and ceilings (the floors are the ground): nobody inside one.
    std::vector<Bounds> walls;
    for (const EnvironmentObject& o : building.environment) {
        if (o.name.find("-floor") != std::string::npos) continue;
        std::vector<Vec3> points;
        for (std::uint32_t t = o.first_triangle; t < o.first_triangle + o.triangle_count; ++t)
            for (int k = 0; k < 3; ++k)
                points.push_back(building.occluder_vertices[building.occluder_indices[3 * t + k]]);
        walls.push_back(bounds_of(points));
    }
    std::size_t ceilings = 0;
    for (const EnvironmentObject& o : building.environment) ceilings += o.name.find("-ceiling") != std::string::npos;
    EXPECT_EQ(ceilings, 3u);
    EXPECT_GT(walls.size(), 10u);
    check_clear(building, walls);
    // The camera walks from the hall into the kitchen.
    const std::vector<Camera> cameras = building.camera_path(60, 1.5f);
    auto in = [](Vec3 e, const Bounds& b) {
        return e.x >= b.min.x && e.x <= b.max.x && e.z >= b.min.z && e.z <= b.max.z;
    };
    EXPECT_TRUE(in(cameras.front().eye, building.cells[0].box));
    EXPECT_TRUE(in(cameras.back().eye, building.cells[1].box));
}

// The complete example of docs/SCENE_FORMAT.md loads (its OBJ files stood in for by cubes).
TEST(SceneFile, DocumentedExampleLoads) {
    std::ifstream in(fs::path(PATCHCULL_SOURCE_DIR) / "docs" / "SCENE_FORMAT.md");
    const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t at = doc.find("## A complete example");
    ASSERT_NE(at, std::string::npos);
    const std::size_t start = doc.find("```json\n", at), end = doc.find("```\n", start + 8);
    ASSERT_NE(start, std::string::npos);
    ASSERT_NE(end, std::string::npos);
    const TempDir dir("example");
    write_file(dir / "models" / "crate.obj", cube_obj());
    write_file(dir / "meshes" / "statue.obj", cube_obj());
    write_file(dir / "yard.json", doc.substr(start + 8, end - start - 8));
    const Scene s = load_scene_file((dir / "yard.json").string());
    EXPECT_EQ(s.name, "yard");
    EXPECT_EQ(s.instances.size(), 4u);
    EXPECT_EQ(s.models.size(), 4u);
    EXPECT_EQ(s.instances[1].name, "monsterfrog#0");
    EXPECT_EQ(s.environment.size(), 3u);
    EXPECT_EQ(s.cells.size(), 2u);
    EXPECT_EQ(s.portals.size(), 1u);
    EXPECT_EQ(s.cells[1].instances, (std::vector<std::size_t>{0, 1, 2}));
}

TEST(SceneFile, ValidSceneSectionsAndModelsLoadedOnce) {
    const TempDir dir("valid");
    write_file(dir / "cube.obj", cube_obj());
    write_file(dir / "a.json", valid_scene());
    const Scene s = load_scene_file((dir / "a.json").string());
    EXPECT_EQ(s.name, "small");
    ASSERT_EQ(s.models.size(), 2u);  // cube.obj (acc) once for "a" and "b", and the teapot
    ASSERT_EQ(s.instances.size(), 3u);
    EXPECT_EQ(s.instances[0].model, s.instances[1].model);
    EXPECT_TRUE(s.instances[0].displaced);
    EXPECT_FALSE(s.instances[1].deforms);
    EXPECT_EQ(s.instances[1].time_offset, 0.5f);
    EXPECT_EQ(s.instances[1].velocity.x, 0.1f);
    EXPECT_EQ(s.animation.period_seconds, 3.0f);
    EXPECT_EQ(s.displacement.width, 64);
    // The matrix form is row-major: the teapot moved by -2 on x.
    EXPECT_EQ(s.instances[2].object_to_world.at(0, 3), -2.0f);
    // Height form: the cube stands 1 high on the ground at the origin.
    ScenePoser poser(s);
    const std::vector<BezierPatch>& patches = poser.pose(0);
    std::vector<Vec3> points;
    for (std::size_t p = 0; p < s.models[0].rest.patches.size(); ++p)
        for (const Vec4& c : patches[p].cp) points.push_back(cartesian(c));
    const Bounds b = bounds_of(points);
    EXPECT_NEAR(b.min.y, 0, 1e-6);
    EXPECT_NEAR(b.max.y, 1, 1e-6);
    // Environment: the quad (2 triangles), the box (12), the OBJ cube (6 quads: 12), in order.
    ASSERT_EQ(s.environment.size(), 3u);
    EXPECT_EQ(s.environment[0].triangle_count, 2u);
    EXPECT_EQ(s.environment[1].triangle_count, 12u);
    EXPECT_EQ(s.environment[2].triangle_count, 12u);
    EXPECT_EQ(s.environment[2].first_triangle, 14u);
    EXPECT_TRUE(s.environment[1].one_sided);   // boxes default to one-sided
    EXPECT_FALSE(s.environment[2].one_sided);  // OBJ meshes default to two-sided
    std::vector<Vec3> mesh;
    for (std::uint32_t t = 14; t < 26; ++t)
        for (int k = 0; k < 3; ++k) mesh.push_back(s.occluder_vertices[s.occluder_indices[3 * t + k]]);
    const Bounds m = bounds_of(mesh);
    EXPECT_EQ(m.min.x, -3.0f);
    EXPECT_EQ(m.max.x, -1.0f);
    EXPECT_EQ(m.max.y, 2.0f);
    ASSERT_EQ(s.cells.size(), 2u);
    EXPECT_EQ(s.cells[0].instances, (std::vector<std::size_t>{0, 2}));
    EXPECT_EQ(s.cells[1].environment, (std::vector<std::size_t>{1}));
    ASSERT_EQ(s.portals.size(), 1u);
    EXPECT_EQ(s.portals[0].cell_b, 1u);
    // A second scheme of the same file is a second model.
    const std::string osd = with(valid_scene(), R"("scheme": "acc")", R"("scheme": "osd")");
    write_file(dir / "b.json", osd);
    EXPECT_EQ(load_scene_file((dir / "b.json").string()).models.size(), 3u);
}

TEST(SceneFile, PathsAreRelativeToTheFile) {
    const TempDir dir("relative");
    write_file(dir / "models" / "cube.obj", cube_obj());
    // The file in scenes/, the model named two ways from there: one model.
    std::string text = with(valid_scene(), R"("model": "cube.obj", "transform": {"position": [0)",
                            R"("model": "../models/cube.obj", "transform": {"position": [0)");
    text = with(text, R"("model": "cube.obj", "scheme")", R"("model": "../scenes/../models/cube.obj", "scheme")");
    text = with(text, R"("obj": "cube.obj")", R"("obj": "../models/cube.obj")");
    write_file(dir / "scenes" / "a.json", text);
    const fs::path cwd = fs::current_path();
    fs::current_path(fs::temp_directory_path());  // not the file's directory
    Scene s;
    EXPECT_NO_THROW(s = load_scene_file((dir / "scenes" / "a.json").string()));
    fs::current_path(cwd);
    EXPECT_EQ(s.models.size(), 2u);
    // Named as the file gives it, the model's error names the resolved path.
    write_file(dir / "scenes" / "b.json",
               with(text, "../models/cube.obj\", \"transform\"", "missing.obj\", \"transform\""));
    try {
        load_scene_file((dir / "scenes" / "b.json").string());
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), (dir / "scenes" / "b.json").string() + ": objects[0].model: " +
                                             (dir / "scenes" / "missing.obj").string() + ": cannot open file");
    }
}

TEST(SceneFile, FarFromTheOriginAndMirrored) {
    const TempDir dir("far");
    // An OBJ environment mesh at 5000 (the OBJ reader recentres it; the file adds the origin back
    // in double), a character and a box at 2000-8000.
    write_file(dir / "far.obj", cube_obj(5000, 2));
    write_file(dir / "cube.obj", cube_obj());
    std::string text = with(valid_scene(), R"("obj": "cube.obj", "transform": {"position": [-3, 0, 3], "scale": 2})",
                            R"("obj": "far.obj", "one_sided": true)");
    text =
        with(text, R"("position": [2, 0, 0], "yaw_degrees": 30)", R"("position": [2000, 0, 8000], "yaw_degrees": 30)");
    text = with(text, R"("min": [3, 0, 3], "max": [4, 1, 4])", R"("min": [3000, 0, 3000], "max": [3001, 1, 3001])");
    write_file(dir / "a.json", text);
    const Scene s = load_scene_file((dir / "a.json").string());
    std::vector<Vec3> mesh;
    const EnvironmentObject& far = s.environment[2];
    for (std::uint32_t t = far.first_triangle; t < far.first_triangle + far.triangle_count; ++t)
        for (int k = 0; k < 3; ++k) mesh.push_back(s.occluder_vertices[s.occluder_indices[3 * t + k]]);
    const Bounds b = bounds_of(mesh);
    EXPECT_EQ(b.min.x, 5000.0f);
    EXPECT_EQ(b.max.x, 5002.0f);
    EXPECT_EQ(b.max.z, 5002.0f);
    // The character's position beyond kSceneWorldFrame: its frame origin (a multiple of
    // kSceneFrameGrid, in double) and a float rest within 8 of it (0 here); placed in the world
    // frame, 8000 again.
    EXPECT_EQ(s.instances[1].origin.z, 8000.0);
    EXPECT_EQ(s.instances[1].origin.x, 2000.0);
    EXPECT_EQ(s.instances[1].object_to_world.at(2, 3), 0.0f);
    EXPECT_EQ(instance_to_world(s.instances[1], 0).at(2, 3), 8000.0f);
    EXPECT_EQ(s.instances[0].origin.x, 0.0);  // near the origin: no grid origin, as before
    // An OBJ environment mesh at 1e5 keeps its exact vertices in double (Scene::occluder_world),
    // one per occluder vertex; one beyond kMaxSceneCoordinate is refused with one line.
    write_file(dir / "far1.obj", cube_obj(1e5 + 0.25, 2));
    write_file(dir / "c.json", with(text, R"("obj": "far.obj")", R"("obj": "far1.obj")"));
    const Scene c = load_scene_file((dir / "c.json").string());
    ASSERT_EQ(c.occluder_world.size(), c.occluder_vertices.size());
    double lo = 1e30;
    for (std::uint32_t t = c.environment[2].first_triangle;
         t < c.environment[2].first_triangle + c.environment[2].triangle_count; ++t)
        for (int k = 0; k < 3; ++k) lo = std::min(lo, c.occluder_world[c.occluder_indices[3 * t + k]].x);
    EXPECT_EQ(lo, 1e5 + 0.25);
    write_file(dir / "far2.obj", cube_obj(1e9, 2));
    write_file(dir / "b.json", with(text, R"("obj": "far.obj")", R"("obj": "far2.obj")"));
    try {
        load_scene_file((dir / "b.json").string());
        ADD_FAILURE() << "a mesh at 1e9 loaded";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("environment[2]: the placed environment object reaches 1e+09; scene files "
                                             "take world coordinates up to 536870912 (2^29"),
                  std::string::npos)
            << e.what();
    }
    // A mirroring matrix keeps boxes outward: the triangles are flipped back.
    text = with(
        valid_scene(), R"("box": {"min": [3, 0, 3], "max": [4, 1, 4]})",
        R"("box": {"min": [3, 0, 3], "max": [4, 1, 4]}, "transform": [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])");
    write_file(dir / "m.json", text);
    const Scene m = load_scene_file((dir / "m.json").string());
    double volume = 0;
    const EnvironmentObject& box = m.environment[1];
    for (std::uint32_t t = box.first_triangle; t < box.first_triangle + box.triangle_count; ++t) {
        const Vec3 a = m.occluder_vertices[m.occluder_indices[3 * t]],
                   c = m.occluder_vertices[m.occluder_indices[3 * t + 2]];
        const Vec3 bb = m.occluder_vertices[m.occluder_indices[3 * t + 1]];
        volume += dot(a, cross(bb, c)) / 6.0;
        EXPECT_LE(a.x, -3.0f);
    }
    EXPECT_NEAR(volume, 1.0, 1e-5);
}

TEST_F(SceneFileErrors, Syntax) {
    const std::string message = load_error(dir_, "{\n  \"name\": \"x\",\n  \"objects\": [,]\n}\n");
    const std::string prefix = (dir_ / "a.json").string() + ":3:15: ";
    EXPECT_EQ(message.substr(0, prefix.size()), prefix) << message;
    EXPECT_NE(message.find("syntax error"), std::string::npos) << message;
    EXPECT_TRUE(is_printable_line(message));
    // Control bytes and invalid UTF-8 in the bad text stay printable.
    const std::string binary = load_error(dir_, "{\"name\": \"\x01\xff\"}");
    EXPECT_TRUE(is_printable_line(binary)) << binary;
    EXPECT_EQ(binary.rfind((dir_ / "a.json").string() + ":1:", 0), 0u) << binary;
    expect("[1, 2]", "expected an object");
    // Deep nesting is refused early (quickly, without memory growing with the depth).
    expect(std::string(200000, '[') + std::string(200000, ']'), "JSON nested deeper than 32 levels");
}

TEST_F(SceneFileErrors, UnknownAndDuplicateKeys) {
    expect(with(valid_scene(), "\"displaced\": true", "\"displace\": true"),
           "objects[0]: unknown key 'displace' (expected name, model, scheme, transform, animation, displaced)");
    expect(with(valid_scene(), "\"name\": \"b\", \"model\"", "\"name\": \"b\", \"name\": \"c\", \"model\""),
           "objects[1]: duplicate key 'name'");
    expect(with(valid_scene(), "\"period_seconds\": 3", "\"period_seconds\": 3, \"period_seconds\": 4"),
           "animation: duplicate key 'period_seconds'");
    expect(
        with(valid_scene(), R"([0, 2, 1], [0, 2, -1]]}])", R"([0, 2, 1], [0, 2, -1]], "cells": ["left", "right"]}])"),
        "portals[0]: duplicate key 'cells'");
}

TEST_F(SceneFileErrors, WrongTypes) {
    expect(with(valid_scene(), "\"transform\": [1, 0, 0, -2, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]",
                "\"transform\": [1, 0, 0]"),
           "objects[2].transform: expected 16 numbers (a row-major 4x4 matrix) or an object");
    expect(with(valid_scene(), "\"yaw_degrees\": 30", "\"yaw_degrees\": \"30\""),
           "objects[1].transform.yaw_degrees: expected a number");
    expect(with(valid_scene(), "\"model\": \"teapot\"", "\"model\": 3"), "objects[2].model: expected a string");
    expect(with(valid_scene(), "\"displaced\": true", "\"displaced\": 1"),
           "objects[0].displaced: expected true or false");
    expect(with(valid_scene(), "\"position\": [2, 0, 0]", "\"position\": [2, 0]"),
           "objects[1].transform.position: expected 3 numbers");
    expect(with(valid_scene(), "\"size\": 64", "\"size\": 64.5"), "displacement.size: expected an integer");
    expect(
        with(valid_scene(),
             R"("portals": [{"cells": ["left", "right"], "corners": [[0, 0, -1], [0, 0, 1], [0, 2, 1], [0, 2, -1]]}])",
             R"("portals": {"cells": 1})"),
        "portals: expected an array");
    expect(with(valid_scene(), "\"animation\": {\"period_seconds\": 3}", "\"animation\": [3]"),
           "animation: expected an object");
}

TEST_F(SceneFileErrors, MissingAndEmpty) {
    expect(with(valid_scene(), "\"name\": \"t\", \"model\": \"teapot\", ", "\"name\": \"t\", "),
           "objects[2]: missing required key 'model'");
    expect(
        with(valid_scene(), "\"camera\":", "\"kamera\":"),
        "unknown key 'kamera' (expected name, objects, environment, displacement, animation, camera, cells, portals)");
    expect("{\"objects\": [], \"camera\": {}}", "objects: expected a non-empty array");
    expect("{\"camera\": {}}", "missing required key 'objects'");
    expect(with(valid_scene(), "\"name\": \"a\", \"model\"", "\"name\": \"\", \"model\""),
           "objects[0].name: expected a non-empty string");
    expect(with(valid_scene(), "{\"orbit\": {\"target\": [0, 0.5, 0], \"distance\": 6, \"height\": 1}, ", "{"),
           "camera: expected exactly one of 'orbit' or 'walk'");
    expect(with(valid_scene(), "\"distance\": 6, ", ""), "camera.orbit: missing required key 'distance'");
}

TEST_F(SceneFileErrors, NumbersOutOfRange) {
    expect(with(valid_scene(), "\"scale\": 0.5", "\"scale\": -0.5"),
           "objects[1].transform.scale: expected a number > 0 and <= 1e+09, got -0.5");
    expect(with(valid_scene(), "\"scale\": 0.5", "\"scale\": 0"),
           "objects[1].transform.scale: expected a number > 0 and <= 1e+09, got 0");
    expect(with(valid_scene(), "\"height\": 1", "\"height\": 0"),
           "objects[0].transform.height: expected a number > 0 and <= 1e+09, got 0");
    expect(with(valid_scene(), "\"yaw_degrees\": 30", "\"yaw_degrees\": 1e39"),
           "objects[1].transform.yaw_degrees: number 1e+39 does not fit a float");
    // nlohmann-json refuses a number beyond a double while parsing, without a position.
    expect(with(valid_scene(), "\"yaw_degrees\": 30", "\"yaw_degrees\": 1e999"),
           "invalid JSON: number overflow parsing '1e999'");
    expect(with(valid_scene(), "\"time_offset\": 0.5", "\"time_offset\": 1e7"),
           "objects[1].animation.time_offset: expected a number >= -1e+06 and <= 1e+06, got 1e+07");
    expect(with(valid_scene(), "\"size\": 64", "\"size\": 100000"),
           "displacement.size: expected an integer between 1 and 4096");
    expect(with(valid_scene(), "\"size\": 64", "\"size\": 0"),
           "displacement.size: expected an integer between 1 and 4096");
    expect(with(valid_scene(), "\"size\": 64", "\"size\": -3"),
           "displacement.size: expected an integer between 1 and 4096");
    expect(with(valid_scene(), "\"size\": 64", "\"size\": 18446744073709551615"),
           "displacement.size: expected an integer between 1 and 4096");
    expect(with(valid_scene(), "\"z_far\": 40", "\"z_far\": 0.05"), "camera.z_far: must be greater than z_near");
}

TEST_F(SceneFileErrors, TransformsAndDegenerateInputs) {
    expect(with(valid_scene(), "\"height\": 1}", "\"height\": 1, \"scale\": 2}"),
           "objects[0].transform: give 'height' or 'scale', not both");
    expect(with(valid_scene(), "0, 0, 0, 1]}", "0, 0, 1, 1]}"),
           "objects[2].transform: the last row must be 0 0 0 1 (an affine matrix)");
    expect(with(valid_scene(), "[1, 0, 0, -2, 0, 1, 0, 0", "[1, 0, 0, -2, 0, 0, 0, 0"),
           "objects[2].transform: the matrix is singular (a zero scale)");
    expect_prefix(with(valid_scene(), "\"scale\": 0.5", "\"scale\": 1e-9"),
                  "objects[1].transform: the placed model is ");
    EXPECT_NE(
        load_error(dir_, with(valid_scene(), "\"scale\": 0.5", "\"scale\": 1e-9"))
            .find(
                "e-09 units across; patchcull takes meshes of at least 1e-06 units across (the kernels work in float)"),
        std::string::npos);
    expect(with(valid_scene(), "\"position\": [2, 0, 0]", "\"position\": [2, 0, 3e11]"),
           "objects[1].transform.position[2]: expected a number >= -536870912 and <= 536870912, got 3e+11");
    // kMaxSceneCoordinate (2^29): beyond it a double world position is coarser than the floats
    // it places.
    expect(with(valid_scene(), "\"position\": [2, 0, 0]", "\"position\": [2, 0, 6e8]"),
           "objects[1].transform.position[2]: expected a number >= -536870912 and <= 536870912, got 6e+08");
    // Cells and portals are world positions (double) within kMaxSceneCoordinate.
    expect(with(valid_scene(), "\"min\": [0, 0, -5], \"max\": [5, 3, 5]", "\"min\": [0, 0, -5], \"max\": [6e8, 3, 5]"),
           "cells[1].max[0]: expected a number >= -536870912 and <= 536870912, got 6e+08");
    const std::string huge =
        with(valid_scene(), "[1, 0, 0, -2, 0, 1, 0, 0, 0, 0, 1, 0", "[5e11, 0, 0, -2, 0, 5e11, 0, 0, 0, 0, 5e11, 0");
    expect_prefix(huge, "objects[2].transform: the placed model reaches ");
    EXPECT_NE(load_error(dir_, huge)
                  .find("e+11; scene files take world coordinates up to 536870912 (2^29: beyond it a double world "
                        "position is coarser than the float data it places)"),
              std::string::npos);
    expect(with(valid_scene(), "\"max\": [4, 1, 4]", "\"max\": [4, 0, 4]"),
           "environment[1].box: max must be greater than min on every axis (a flat or empty box)");
    expect(with(valid_scene(), "[5, 0, 5], [5, 0, -5]]", "[-5, 0, -5], [-5, 0, -5]]"),
           "environment[0].quad: the corners span no area");
    expect(with(valid_scene(), "\"name\": \"box\", \"box\"", "\"name\": \"box\", \"quad\": [], \"box\""),
           "environment[1]: expected exactly one of 'box', 'quad' or 'obj'");
}

TEST_F(SceneFileErrors, NamesAndReferences) {
    expect(with(valid_scene(), "\"name\": \"b\"", "\"name\": \"a\""),
           "objects[1].name: duplicate object name 'a' (also objects[0])");
    expect(with(valid_scene(), "\"name\": \"box\"", "\"name\": \"ground\""),
           "environment[1].name: duplicate environment name 'ground' (also environment[0])");
    expect(with(valid_scene(), "\"objects\": [\"b\"]", "\"objects\": [\"c\"]"),
           "cells[1].objects[0]: no object named 'c'");
    expect(with(valid_scene(), "\"environment\": [\"box\"]", "\"environment\": [\"box\", \"box\"]"),
           "cells[1].environment[1]: 'box' is listed twice");
    expect(with(valid_scene(), "[\"left\", \"right\"]", "[\"left\", \"up\"]"),
           "portals[0].cells[1]: no cell named 'up'");
    expect(with(valid_scene(), "[\"left\", \"right\"]", "[\"left\", \"left\"]"),
           "portals[0].cells: a portal joins two different cells");
    expect(with(valid_scene(), "\"scheme\": \"acc\"", "\"scheme\": \"loop\""),
           "objects[1].scheme: unknown scheme 'loop' (acc or osd)");
    expect(with(valid_scene(), "\"displacement\": {\"map\": \"procedural\", \"scale\": 0.02, \"size\": 64},", ""),
           "objects[0].displaced: true, but the scene has no displacement map (\"displacement\")");
}

TEST_F(SceneFileErrors, WalkCamera) {
    const std::string orbit = "\"orbit\": {\"target\": [0, 0.5, 0], \"distance\": 6, \"height\": 1}";
    const std::string walk = "\"walk\": {\"start\": [0, 1, 4], \"step\": [0, 0, -0.1], \"direction\": [0, 0, -1]}";
    write_file(dir_ / "w.json", with(valid_scene(), orbit, walk));
    const Scene s = load_scene_file((dir_ / "w.json").string());
    ASSERT_TRUE(s.camera.walk);
    const std::vector<Camera> cams = s.camera_path(3, 1.0f);
    EXPECT_EQ(cams[2].eye.z, 4.0f - 2 * 0.1f);
    EXPECT_EQ(cams[2].target.z, cams[2].eye.z - 1);
    expect(with(valid_scene(), orbit, with(walk, "[0, 0, -1]", "[0, -2, 0]")),
           "camera.walk.direction: expected a direction that is not zero or vertical");
    expect(with(valid_scene(), orbit, with(walk, "\"step\": [0, 0, -0.1], ", "")),
           "camera.walk: missing required key 'step'");
}

TEST_F(SceneFileErrors, UnreadableFilesAndModels) {
    const std::string missing = (dir_ / "none.json").string();
    try {
        load_scene_file(missing);
        ADD_FAILURE();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), missing + ": cannot open file");
    }
    try {
        load_scene_file(dir_.string());
        ADD_FAILURE();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), dir_.string() + ": not a regular file (patchcull reads scene files only)");
    }
    // A model beyond load_model's limits: its message, after the file and JSON path.
    write_file(dir_ / "huge.obj", cube_obj(0, 1e12));
    expect(with(valid_scene(), "\"model\": \"teapot\"", "\"model\": \"huge.obj\""),
           "objects[2].model: " + (dir_ / "huge.obj").string() +
               ": the mesh is 1e+12 units across; patchcull takes meshes up to 2e+11 units across (the kernels work in "
               "float)");
    write_file(dir_ / "bad.obj", "v 0 0 0\nv 1 0 nan\n");
    expect(with(valid_scene(), "\"obj\": \"cube.obj\"", "\"obj\": \"bad.obj\""),
           "environment[2].obj: " + (dir_ / "bad.obj").string() + ":2: non-finite coordinate 'nan'");
    expect(with(valid_scene(), "\"map\": \"procedural\", \"scale\": 0.02, \"size\": 64",
                "\"map\": \"h.png\", \"scale\": 0.02"),
           "displacement.map: " + (dir_ / "h.png").string() + ": cannot read image: cannot open file");
}

// Mutants of a valid scene file never crash: each loads or throws Error with one printable line
// that names the file. std::mt19937's output is fixed by the standard: the mutants are the same
// everywhere.
TEST(SceneFile, MutantsLoadOrFailWithOneLine) {
    const TempDir dir("mutants");
    write_file(dir / "cube.obj", cube_obj());
    const std::string base = valid_scene();
    const char* const tokens[] = {"1e39",
                                  "-1e39",
                                  "1e-50",
                                  "nan",
                                  "-0",
                                  "0",
                                  "-1",
                                  "1e308",
                                  "99999999999999999999",
                                  "\"\"",
                                  "[]",
                                  "{}",
                                  "null",
                                  "true",
                                  "\"teapot\"",
                                  "\"../cube.obj\"",
                                  "\"/dev/zero\"",
                                  "[0, 0, 0]",
                                  "\"\\u0001\"",
                                  "\"\xff\""};
    std::mt19937 rng(2024);
    auto below = [&](std::size_t n) { return n == 0 ? std::size_t{0} : static_cast<std::size_t>(rng() % n); };
    int loaded = 0, failed = 0;
    for (int m = 0; m < 300; ++m) {
        std::string text = base;
        const int edits = below(4) == 0 ? 2 : 1;
        for (int e = 0; e < edits; ++e) {
            switch (below(10)) {
                case 6:
                case 7:
                case 8:
                case 9: {  // replace a number with another number (often still a valid scene)
                    std::vector<std::size_t> starts;
                    for (std::size_t i = 1; i < text.size(); ++i)
                        if ((text[i] >= '0' && text[i] <= '9') && !(text[i - 1] >= '0' && text[i - 1] <= '9') &&
                            text[i - 1] != '.' && text[i - 1] != '-' && text[i - 1] != 'e')
                            starts.push_back(i);
                    if (starts.empty()) break;
                    const std::size_t at = starts[below(starts.size())];
                    std::size_t end = at;
                    while (end < text.size() && (std::isdigit(static_cast<unsigned char>(text[end])) ||
                                                 text[end] == '.' || text[end] == 'e'))
                        ++end;
                    const char* const numbers[] = {"0", "1", "2", "0.5", "3.25", "7", "1e-3", "1e5", "45", "0.01"};
                    text.replace(at, end - at, numbers[below(std::size(numbers))]);
                    break;
                }
                case 0:  // flip a bit
                    text[below(text.size())] ^= static_cast<char>(1u << below(8));
                    break;
                case 1:  // truncate
                    text.resize(below(text.size() + 1));
                    break;
                case 2: {  // replace a number, string or literal with another token
                    std::vector<std::size_t> starts;
                    for (std::size_t i = 1; i < text.size(); ++i)
                        if ((text[i - 1] == ' ' || text[i - 1] == '[') && text[i] != ' ') starts.push_back(i);
                    if (starts.empty()) break;
                    const std::size_t at = starts[below(starts.size())];
                    std::size_t end = at;
                    while (end < text.size() && text[end] != ',' && text[end] != ']' && text[end] != '}' &&
                           text[end] != '\n')
                        ++end;
                    text.replace(at, end - at, tokens[below(std::size(tokens))]);
                    break;
                }
                case 3: {  // duplicate a slice
                    const std::size_t at = below(text.size() + 1),
                                      n = below(std::min<std::size_t>(80, text.size() - at) + 1);
                    text.insert(at, text.substr(at, n));
                    break;
                }
                case 4: {  // delete a slice
                    const std::size_t at = below(text.size() + 1),
                                      n = below(std::min<std::size_t>(40, text.size() - at) + 1);
                    text.erase(at, n);
                    break;
                }
                default:  // insert a control byte or a piece of invalid UTF-8
                    text.insert(below(text.size() + 1), 1, "\x01\x1b\xff\xc3\x7f\t"[below(6)]);
                    break;
            }
        }
        const fs::path path = dir / "m.json";
        write_file(path, text);
        try {
            load_scene_file(path.string());
            ++loaded;
        } catch (const Error& e) {
            ++failed;
            const std::string message = e.what();
            ASSERT_TRUE(is_printable_line(message)) << "mutant " << m << ": " << message;
            ASSERT_EQ(message.rfind(path.string() + ":", 0), 0u) << "mutant " << m << ": " << message;
        }
    }
    // Both outcomes happen (the mutations are neither all harmless nor all fatal).
    EXPECT_GT(loaded, 30);
    EXPECT_GT(failed, 100);
}
