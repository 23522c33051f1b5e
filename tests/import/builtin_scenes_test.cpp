// The built-in `city` and `building` scenes (patchcull/import/builtin_scenes.h): their layout contracts
// checked on the posed patches over the frames the CLI renders (60 frames at 1/12 s): no
// character inside a building or wall, on the ground, the camera in the streets or rooms and
// never inside a character; environment objects tile the occluders, boxes are outward; cells and
// portals are consistent. Small parameters keep the tests fast; one test builds the defaults.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <set>
#include <string>

#include "patchcull/core/error.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_poser.h"

using namespace patchcull;

namespace {

constexpr int kFrames = 60;
constexpr float kFrameSeconds = 1.0f / 12.0f;

Bounds range_bounds(const std::vector<BezierPatch>& patches, std::size_t first, std::size_t count) {
    Bounds b{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (std::size_t p = first; p < first + count; ++p)
        for (const Vec4& c : patches[p].cp) {
            const Vec3 q = cartesian(c);
            b.min = {std::min(b.min.x, q.x), std::min(b.min.y, q.y), std::min(b.min.z, q.z)};
            b.max = {std::max(b.max.x, q.x), std::max(b.max.y, q.y), std::max(b.max.z, q.z)};
        }
    return b;
}

bool overlap(const Bounds& a, const Bounds& b) {
    return a.min.x < b.max.x && b.min.x < a.max.x && a.min.y < b.max.y && b.min.y < a.max.y && a.min.z < b.max.z &&
           b.min.z < a.max.z;
}

bool inside(Vec3 p, const Bounds& b) {
    return p.x >= b.min.x && p.x <= b.max.x && p.y >= b.min.y && p.y <= b.max.y && p.z >= b.min.z && p.z <= b.max.z;
}

// Bounds of an environment object's vertices.
Bounds object_bounds(const Scene& scene, const EnvironmentObject& object) {
    std::vector<Vec3> points;
    for (std::uint32_t t = object.first_triangle; t < object.first_triangle + object.triangle_count; ++t)
        for (int k = 0; k < 3; ++k) points.push_back(scene.occluder_vertices[scene.occluder_indices[3 * t + k]]);
    return compute_bounds(points);
}

// Signed volume of an environment object's triangles (divergence theorem, in double).
double signed_volume(const Scene& scene, const EnvironmentObject& object) {
    double v = 0;
    for (std::uint32_t t = object.first_triangle; t < object.first_triangle + object.triangle_count; ++t) {
        const Vec3 a = scene.occluder_vertices[scene.occluder_indices[3 * t]];
        const Vec3 b = scene.occluder_vertices[scene.occluder_indices[3 * t + 1]];
        const Vec3 c = scene.occluder_vertices[scene.occluder_indices[3 * t + 2]];
        v += (double(a.x) * (double(b.y) * c.z - double(b.z) * c.y) -
              double(a.y) * (double(b.x) * c.z - double(b.z) * c.x) +
              double(a.z) * (double(b.x) * c.y - double(b.y) * c.x)) /
             6.0;
    }
    return v;
}

// Environment objects tile the occluder triangles in order; names are unique; boxes are
// closed outward solids (volume = the box's, > 0) and one-sided.
void check_environment(const Scene& scene) {
    std::uint32_t next = 0;
    std::set<std::string> names;
    for (const EnvironmentObject& o : scene.environment) {
        EXPECT_EQ(o.first_triangle, next) << o.name;
        EXPECT_GT(o.triangle_count, 0u) << o.name;
        next = o.first_triangle + o.triangle_count;
        EXPECT_TRUE(names.insert(o.name).second) << "duplicate " << o.name;
        if (o.name == "ground") {
            const Vec3 a = scene.occluder_vertices[scene.occluder_indices[3 * o.first_triangle]];
            const Vec3 b = scene.occluder_vertices[scene.occluder_indices[3 * o.first_triangle + 1]];
            const Vec3 c = scene.occluder_vertices[scene.occluder_indices[3 * o.first_triangle + 2]];
            EXPECT_GT(cross(b - a, c - a).y, 0.0f) << "the ground faces +y";
            EXPECT_TRUE(o.one_sided);
        } else {
            ASSERT_EQ(o.triangle_count, 12u) << o.name;
            const Bounds b = object_bounds(scene, o);
            const double box = double(b.max.x - b.min.x) * (b.max.y - b.min.y) * (b.max.z - b.min.z);
            EXPECT_GT(box, 0) << o.name;
            EXPECT_NEAR(signed_volume(scene, o), box, 1e-4 * box + 1e-9) << o.name << ": counter-clockwise outward";
            EXPECT_TRUE(o.one_sided) << o.name;
        }
    }
    EXPECT_EQ(next, scene.occluder_indices.size() / 3);
    std::set<std::string> instance_names;
    for (const SceneInstance& i : scene.instances) EXPECT_TRUE(instance_names.insert(i.name).second) << i.name;
}

// Over the CLI's frames: no character's posed bounds overlap a solid (building, wall piece,
// post); each stands on the ground (its lowest control point near y = 0) and on the ground quad;
// the eye is inside no character and no solid.
void check_frames(const Scene& scene, const std::vector<Bounds>& solids, const Bounds& ground) {
    ScenePoser poser(scene);
    const std::vector<Camera> cameras = scene.camera_path(kFrames, 16.0f / 9.0f);
    std::size_t checked = 0;
    for (int f = 0; f < kFrames; ++f) {
        const std::vector<BezierPatch>& patches = poser.pose(f * kFrameSeconds);
        std::size_t first = 0;
        for (const Bounds& s : solids) ASSERT_FALSE(inside(cameras[f].eye, s)) << "frame " << f << ": eye in a solid";
        for (const SceneInstance& instance : scene.instances) {
            const std::size_t count = scene.models[instance.model].rest.patches.size();
            const Bounds b = range_bounds(patches, first, count);
            first += count;
            for (const Bounds& s : solids)
                ASSERT_FALSE(overlap(b, s)) << "frame " << f << ": " << instance.name << " inside a solid at ("
                                            << b.min.x << ", " << b.min.z << ")";
            // The animation's bend swings the feet a little up and down (up to about 0.05).
            ASSERT_NEAR(b.min.y, 0.0f, 0.1f) << instance.name;
            ASSERT_TRUE(b.min.x > ground.min.x && b.max.x < ground.max.x && b.min.z > ground.min.z &&
                        b.max.z < ground.max.z)
                << "frame " << f << ": " << instance.name << " off the ground";
            ASSERT_FALSE(inside(cameras[f].eye, b)) << "frame " << f << ": eye inside " << instance.name;
            ++checked;
        }
    }
    EXPECT_EQ(checked, scene.instances.size() * kFrames);
}

std::vector<Bounds> solids_of(const Scene& scene, const std::string& prefix_a, const std::string& prefix_b) {
    std::vector<Bounds> solids;
    for (const EnvironmentObject& o : scene.environment)
        if (o.name.rfind(prefix_a, 0) == 0 || o.name.rfind(prefix_b, 0) == 0) solids.push_back(object_bounds(scene, o));
    return solids;
}

Bounds ground_of(const Scene& scene) {
    for (const EnvironmentObject& o : scene.environment)
        if (o.name == "ground") return object_bounds(scene, o);
    ADD_FAILURE() << "no ground";
    return {};
}

CityParams small_city() {
    CityParams p;
    p.blocks_x = 2;
    p.blocks_z = 2;
    p.characters = 24;
    p.seed = 3;
    return p;
}

}  // namespace

TEST(CityScene, SmallCityKeepsItsCharactersInTheStreets) {
    const Scene scene = make_city_scene(Scheme::acc, small_city());
    EXPECT_EQ(scene.name, "city");
    ASSERT_EQ(scene.instances.size(), 24u);
    EXPECT_EQ(scene.environment.size(), 4u + 1u);  // 4 buildings and the ground
    check_environment(scene);
    // Characters: both models, a mix of rigid and deforming, walking and standing; frogs displaced.
    int rigid = 0, walking = 0, frogs = 0;
    std::set<float> phases;
    for (const SceneInstance& i : scene.instances) {
        rigid += i.deforms ? 0 : 1;
        walking += (i.velocity.x != 0 || i.velocity.z != 0) ? 1 : 0;
        frogs += i.model == 1 ? 1 : 0;
        EXPECT_EQ(i.displaced, i.model == 1) << i.name;
        EXPECT_EQ(i.velocity.y, 0.0f);
        EXPECT_TRUE(i.velocity.x == 0 || i.velocity.z == 0) << i.name << " walks along a street";
        phases.insert(i.time_offset);
    }
    EXPECT_GT(rigid, 0);
    EXPECT_LT(rigid, 24);
    EXPECT_GT(walking, 0);
    EXPECT_LT(walking, 24);
    EXPECT_EQ(frogs, 12);
    EXPECT_LE(phases.size(), 6u);
    EXPECT_FALSE(scene.displacement.empty());
    EXPECT_TRUE(scene.camera.walk);
    check_frames(scene, solids_of(scene, "building#", "building#"), ground_of(scene));
}

TEST(CityScene, CameraWalksAStreetAndBuildingsHideCharacters) {
    CityParams p = small_city();
    p.blocks_x = 3;
    p.blocks_z = 3;
    p.characters = 40;
    const Scene scene = make_city_scene(Scheme::acc, p);
    const std::vector<Camera> cameras = scene.camera_path(kFrames, 16.0f / 9.0f);
    ASSERT_EQ(cameras.size(), static_cast<std::size_t>(kFrames));
    // Straight along -z at eye height, looking down the street.
    EXPECT_FLOAT_EQ(cameras[0].eye.x, cameras[59].eye.x);
    EXPECT_FLOAT_EQ(cameras[0].eye.y, 0.8f);
    EXPECT_LT(cameras[59].eye.z, cameras[0].eye.z - 5.0f);
    for (const Camera& c : cameras) EXPECT_LT(c.target.z, c.eye.z);
    // Many characters are behind the camera or hidden: a character's centre is hidden from the
    // eye when the segment between them crosses a building (sampled).
    const std::vector<Bounds> buildings = solids_of(scene, "building#", "building#");
    ScenePoser poser(scene);
    const std::vector<BezierPatch>& patches = poser.pose(0);
    std::size_t first = 0, behind = 0, hidden = 0;
    for (const SceneInstance& instance : scene.instances) {
        const std::size_t count = scene.models[instance.model].rest.patches.size();
        const Vec3 centre = range_bounds(patches, first, count).center();
        first += count;
        if (dot(centre - cameras[0].eye, cameras[0].target - cameras[0].eye) < 0) {
            ++behind;
            continue;
        }
        bool blocked = false;
        for (int s = 1; s < 64 && !blocked; ++s) {
            const Vec3 q = cameras[0].eye + (centre - cameras[0].eye) * (s / 64.0f);
            for (const Bounds& b : buildings) blocked = blocked || inside(q, b);
        }
        hidden += blocked ? 1 : 0;
    }
    EXPECT_GT(behind, 0u);
    EXPECT_GT(hidden, scene.instances.size() / 4) << behind << " behind";
}

TEST(CityScene, SameSeedSameSceneOtherSeedOther) {
    const Scene a = make_city_scene(Scheme::acc, small_city());
    const Scene b = make_city_scene(Scheme::acc, small_city());
    CityParams p = small_city();
    p.seed = 4;
    const Scene c = make_city_scene(Scheme::acc, p);
    ASSERT_EQ(a.instances.size(), b.instances.size());
    bool differ = false;
    for (std::size_t i = 0; i < a.instances.size(); ++i) {
        for (int k = 0; k < 16; ++k)
            EXPECT_EQ(a.instances[i].object_to_world.m[k], b.instances[i].object_to_world.m[k]);
        differ = differ || a.instances[i].object_to_world.m[12] != c.instances[i].object_to_world.m[12];
    }
    EXPECT_TRUE(differ);
    EXPECT_EQ(a.occluder_vertices.size(), b.occluder_vertices.size());
}

TEST(CityScene, BadParametersAndNoRoomAreErrors) {
    CityParams p = small_city();
    p.blocks_x = 0;
    EXPECT_THROW(make_city_scene(Scheme::acc, p), Error);
    p = small_city();
    p.street_width = NAN;
    EXPECT_THROW(make_city_scene(Scheme::acc, p), Error);
    p = small_city();
    p.rigid_fraction = 1.5f;
    EXPECT_THROW(make_city_scene(Scheme::acc, p), Error);
    p = small_city();
    p.characters = 5000;  // 2 x 2 blocks cannot hold them
    try {
        make_city_scene(Scheme::acc, p);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("no room"), std::string::npos) << e.what();
    }
}

TEST(CityScene, DefaultCityHasAtLeast200CharactersAndInteractivePatchCounts) {
    const Scene scene = make_city_scene();
    EXPECT_GE(scene.instances.size(), 200u);
    EXPECT_GE(scene.patch_count(), 100000u);
    EXPECT_LE(scene.patch_count(), 1000000u);
    EXPECT_EQ(scene.environment.size(), 36u + 1u);
    check_environment(scene);
    // Every character stays out of the buildings over the rendered frames (every fourth and the
    // last, to keep the test short; SmallCity checks every frame).
    const std::vector<Bounds> buildings = solids_of(scene, "building#", "building#");
    ScenePoser poser(scene);
    std::vector<float> times;
    for (int f = 0; f < kFrames; f += 4) times.push_back(f * kFrameSeconds);
    times.push_back((kFrames - 1) * kFrameSeconds);
    for (float t : times) {
        const std::vector<BezierPatch>& patches = poser.pose(t);
        std::size_t first = 0;
        for (const SceneInstance& instance : scene.instances) {
            const std::size_t count = scene.models[instance.model].rest.patches.size();
            const Bounds b = range_bounds(patches, first, count);
            first += count;
            for (const Bounds& s : buildings) ASSERT_FALSE(overlap(b, s)) << instance.name << " at t " << t;
        }
    }
}

// Not a check: the pose time of the default city and building (run with --gtest_also_run_disabled_tests).
TEST(CityScene, DISABLED_PoseTime) {
    const Scene scene = make_city_scene();
    ScenePoser poser(scene);
    poser.pose(0);
    const auto start = std::chrono::steady_clock::now();
    const int frames = 24;
    for (int f = 1; f <= frames; ++f) poser.pose(f * kFrameSeconds);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / frames;
    // The same scene with every instance at its own phase: one evaluation per instance.
    Scene distinct = scene;
    for (std::size_t i = 0; i < distinct.instances.size(); ++i)
        distinct.instances[i].time_offset += 1e-3f * static_cast<float>(i);
    ScenePoser distinct_poser(distinct);
    distinct_poser.pose(0);
    const auto start2 = std::chrono::steady_clock::now();
    for (int f = 1; f <= frames; ++f) distinct_poser.pose(f * kFrameSeconds);
    const double ms2 =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start2).count() / frames;
    std::cout << "city: " << scene.instances.size() << " instances, " << scene.patch_count() << " patches, pose " << ms
              << " ms/frame (shared phases), " << ms2 << " ms/frame (every instance its own phase)\n";
    const Scene building = make_building_scene();
    ScenePoser building_poser(building);
    building_poser.pose(0);
    const auto start3 = std::chrono::steady_clock::now();
    for (int f = 1; f <= frames; ++f) building_poser.pose(f * kFrameSeconds);
    const double ms3 =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start3).count() / frames;
    std::cout << "building: " << building.instances.size() << " instances, " << building.patch_count() << " patches, "
              << building.environment.size() << " environment objects, " << building.occluder_indices.size() / 3
              << " triangles, pose " << ms3 << " ms/frame\n";
}

TEST(BuildingScene, RoomsDoorsAndWindows) {
    BuildingParams p;
    p.rooms_x = 3;
    p.rooms_z = 2;
    p.characters_per_room = 3;
    const Scene scene = make_building_scene(Scheme::acc, p);
    EXPECT_EQ(scene.name, "building");
    check_environment(scene);
    ASSERT_EQ(scene.cells.size(), 6u);
    // Portals: 3 doors between the rows, 2 x 2 doors or windows between the columns.
    ASSERT_EQ(scene.portals.size(), 3u + 4u);
    std::vector<int> degree(scene.cells.size(), 0);
    for (const ScenePortal& portal : scene.portals) {
        ASSERT_LT(portal.cell_a, scene.cells.size());
        ASSERT_LT(portal.cell_b, scene.cells.size());
        ASSERT_NE(portal.cell_a, portal.cell_b);
        ++degree[portal.cell_a];
        ++degree[portal.cell_b];
        const Bounds& a = scene.cells[portal.cell_a].box;
        const Bounds& b = scene.cells[portal.cell_b].box;
        // The rectangle lies on the two cells' shared face and faces cell_a.
        Vec3 centre{};
        for (const Vec3& c : portal.corners) {
            EXPECT_TRUE(inside(c, a) && inside(c, b));
            centre += c * 0.25f;
        }
        const Vec3 n = cross(portal.corners[1] - portal.corners[0], portal.corners[2] - portal.corners[0]);
        EXPECT_GT(dot(n, a.center() - centre), 0.0f) << "counter-clockwise seen from cell_a";
        EXPECT_NEAR(length(portal.corners[2] - portal.corners[0]), length(portal.corners[3] - portal.corners[1]),
                    1e-5f);
    }
    for (int d : degree) EXPECT_GE(d, 1);
    // Every environment object is listed by a cell; each cell lists its floor and ceiling; the
    // instances listed by a cell stand in its box; every instance is in one cell.
    std::vector<int> listed(scene.environment.size(), 0), instance_cells(scene.instances.size(), 0);
    for (const SceneCell& cell : scene.cells) {
        int floors = 0;
        for (std::size_t e : cell.environment) {
            ASSERT_LT(e, scene.environment.size());
            ++listed[e];
            floors += scene.environment[e].name.rfind("floor#", 0) == 0 ||
                      scene.environment[e].name.rfind("ceiling#", 0) == 0;
        }
        EXPECT_EQ(floors, 2) << cell.name;
        for (std::size_t i : cell.instances) {
            ASSERT_LT(i, scene.instances.size());
            ++instance_cells[i];
            const Vec3 p{scene.instances[i].object_to_world.at(0, 3), 0.5f,
                         scene.instances[i].object_to_world.at(2, 3)};
            EXPECT_TRUE(inside(p, cell.box)) << scene.instances[i].name << " in " << cell.name;
        }
    }
    for (int n : listed) EXPECT_GE(n, 1);
    for (int n : instance_cells) EXPECT_EQ(n, 1);
    EXPECT_GE(scene.instances.size(), 12u);
    // Cameras: a walk inside the cells through the doors; characters never in a wall.
    ASSERT_TRUE(scene.camera.walk);
    for (const Camera& c : scene.camera_path(kFrames, 1.5f)) {
        bool in_cell = false;
        for (const SceneCell& cell : scene.cells) in_cell = in_cell || inside(c.eye, cell.box);
        EXPECT_TRUE(in_cell);
    }
    Bounds all{{-1e9f, -1e9f, -1e9f}, {1e9f, 1e9f, 1e9f}};
    check_frames(scene, solids_of(scene, "wall#", "ceiling#"), all);  // the floor slabs are the ground
}

TEST(BuildingScene, DefaultBuildingIsInteractiveAndWalksThroughTheMiddleColumn) {
    const Scene scene = make_building_scene();
    EXPECT_EQ(scene.cells.size(), 9u);
    EXPECT_GE(scene.patch_count(), 80000u);
    EXPECT_LE(scene.patch_count(), 1000000u);
    const std::vector<Camera> cameras = scene.camera_path(kFrames, 1.5f);
    // From the south room of the middle column to its north room.
    auto cell_of = [&](Vec3 p) {
        for (std::size_t c = 0; c < scene.cells.size(); ++c)
            if (inside(p, scene.cells[c].box)) return static_cast<int>(c);
        return -1;
    };
    EXPECT_EQ(cell_of(cameras.front().eye), 7);
    EXPECT_EQ(cell_of(cameras.back().eye), 1);
}

TEST(BuiltinScenes, ByName) {
    EXPECT_EQ(make_builtin_scene("default").name, "default");
    try {
        make_builtin_scene("town");
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "unknown scene 'town' (default, city or building)");
    }
}
