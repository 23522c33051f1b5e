// The built-in scenes (patchcull/import/builtin_scenes.h): `default` (Niessner & Loop, Fig. 1 (c)),
// the one-model scene, `city` and `building`, and the lookup of built-in scenes by name.
//
// The city and the building place characters by rejection sampling with std::mt19937 (raw output
// only: a seed gives the same scene everywhere) and square clearances: a character at p with reach
// r (animated_reach) is kept out of a box B when p lies outside B grown by r + kClearance on x
// and z (why that suffices at any yaw and pose: docs/SCENES.md).
#include "patchcull/import/builtin_scenes.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "patchcull/core/error.h"
#include "scene_builder.h"

namespace patchcull {
namespace {

using namespace detail;

constexpr float kClearance = 0.1f;      // gap between a character's reach and a building or wall
constexpr float kPhaseSeconds = 0.37f;  // time offset between phases (the default scene's step)
constexpr int kReachSamples = 48;       // animation samples per period for the reach

struct Rng {
    std::mt19937 engine;
    explicit Rng(unsigned seed) : engine(seed) {}
    float uniform() { return static_cast<float>(engine() >> 8) * (1.0f / 16777216.0f); }  // [0, 1)
    float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
    int below(int n) { return static_cast<int>(engine() % static_cast<unsigned>(n)); }
};

// An axis-aligned rectangle in the xz plane.
struct Rect {
    float x0, z0, x1, z1;
    bool contains_grown(float x, float z, float grow) const {
        return x > x0 - grow && x < x1 + grow && z > z0 - grow && z < z1 + grow;
    }
};

void check_range(const char* name, double value, double lo, double hi) {
    if (!(value >= lo && value <= hi))
        throw Error(std::string(name) + ": must be between " + std::to_string(lo) + " and " + std::to_string(hi) +
                    ", got " + std::to_string(value));
}

// Start positions placed so far with their reaches, bucketed in square cells at least as wide as
// any two reaches together, so a new position is checked against its own and the 8 neighbouring
// cells only (placement stays linear in the number of characters).
class SpacingGrid {
public:
    SpacingGrid(float x0, float z0, float width_x, float width_z, float max_reach)
        : x0_(x0),
          z0_(z0),
          cell_(std::max({2 * max_reach, width_x / 256, width_z / 256, 1e-3f})),
          nx_(static_cast<int>(width_x / cell_) + 1),
          nz_(static_cast<int>(width_z / cell_) + 1),
          cells_(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(nz_)) {}

    // True when the square of half side r around p is clear of every placed one's square.
    bool clear(Vec3 p, float r) const {
        const int cx = cell_x(p.x), cz = cell_z(p.z);
        for (int z = std::max(0, cz - 1); z <= std::min(nz_ - 1, cz + 1); ++z)
            for (int x = std::max(0, cx - 1); x <= std::min(nx_ - 1, cx + 1); ++x)
                for (const auto& [q, rq] : cells_[static_cast<std::size_t>(z) * nx_ + x])
                    if (std::fabs(q.x - p.x) < r + rq && std::fabs(q.z - p.z) < r + rq) return false;
        return true;
    }
    void add(Vec3 p, float r) { cells_[static_cast<std::size_t>(cell_z(p.z)) * nx_ + cell_x(p.x)].push_back({p, r}); }

private:
    int cell_x(float x) const { return std::clamp(static_cast<int>((x - x0_) / cell_), 0, nx_ - 1); }
    int cell_z(float z) const { return std::clamp(static_cast<int>((z - z0_) / cell_), 0, nz_ - 1); }
    float x0_, z0_, cell_;
    int nx_, nz_;
    std::vector<std::vector<std::pair<Vec3, float>>> cells_;
};

// A character of the scene: model, where it stands at t = 0, heading, and motion.
struct Character {
    std::size_t model;
    Vec3 position;
    float yaw_degrees;
    Vec3 velocity;
    bool deforms;
    float time_offset;
};

// Adds characters as instances (names counted per model; the frogs displaced) with
// instance_to_world(instance, 0) = translation(position) * rotation_y(yaw) * standing.
void add_characters(Scene& scene, const std::vector<Character>& characters, const Mat4 standing[2]) {
    int copies[2] = {0, 0};
    for (const Character& c : characters) {
        SceneInstance instance;
        instance.model = c.model;
        // At t = 0 the motion has moved it by velocity * time_offset already: start behind.
        instance.object_to_world =
            translation(c.position - c.velocity * c.time_offset) * rotation_y(c.yaw_degrees) * standing[c.model];
        instance.time_offset = c.time_offset;
        instance.displaced = c.model == 1;
        instance.deforms = c.deforms;
        instance.velocity = c.velocity;
        instance.name = std::string(c.model == 0 ? "bigguy#" : "monsterfrog#") + std::to_string(copies[c.model]++);
        scene.instances.push_back(std::move(instance));
    }
}

// The characters' standing transforms (BigGuy 1 high, MonsterFrog 0.6) and their reaches.
void character_shapes(const Scene& scene, Mat4 standing[2], float reach[2]) {
    standing[0] = standing_transform(scene.models[0], 1.0f);
    standing[1] = standing_transform(scene.models[1], 0.6f);
    for (int m = 0; m < 2; ++m) reach[m] = animated_reach(scene.models[m], standing[m], scene.animation, kReachSamples);
}

}  // namespace

Scene make_default_scene(Scheme scheme) {
    Scene scene;
    scene.name = "default";
    load_characters(scene, scheme);
    const Mat4 bigguy = standing_transform(scene.models[0], 1.0f);
    const Mat4 frog = standing_transform(scene.models[1], 0.6f);  // a frog is lower than BigGuy
    // Two loose rows facing the camera's side (+z); the front row partly hides the back row,
    // the wall hides the front row's legs, the pillars cut into both.
    struct Placement {
        std::size_t model;
        Vec3 position;
        float yaw_degrees;
    };
    const Placement placements[] = {
        {0, {-1.3f, 0, -1.4f}, 20}, {1, {0.1f, 0, -1.6f}, -15}, {0, {1.5f, 0, -1.3f}, -30},
        {1, {-0.7f, 0, -0.1f}, 35}, {0, {0.6f, 0, 0.0f}, 0},    {1, {1.9f, 0, 0.2f}, -40},
    };
    float offset = 0;
    int copies[2] = {0, 0};
    for (const Placement& p : placements) {
        const Mat4& standing = p.model == 0 ? bigguy : frog;
        SceneInstance instance;
        instance.model = p.model;
        instance.object_to_world = translation(p.position) * rotation_y(p.yaw_degrees) * standing;
        instance.time_offset = offset;
        instance.displaced = p.model == 1;  // the frogs
        instance.name = std::string(p.model == 0 ? "bigguy#" : "monsterfrog#") + std::to_string(copies[p.model]++);
        scene.instances.push_back(std::move(instance));
        offset += 0.37f;
    }
    scene.displacement = make_procedural_displacement(512, kDefaultSceneDisplaceScale);
    scene.displacement_name = "procedural";
    add_ground(scene, 6.0f);
    add_box(scene, "wall", {-2.6f, 0, 0.75f}, {0.9f, 0.42f, 0.9f});         // low wall in front of the front row
    add_box(scene, "pillar#0", {-0.45f, 0, -0.85f}, {-0.2f, 1.5f, -0.6f});  // pillar between the rows
    add_box(scene, "pillar#1", {1.0f, 0, -0.75f}, {1.2f, 1.3f, -0.55f});    // a second, thinner pillar
    // Low and close, with a 45-degree vertical field of view: the wall hides the front row's legs,
    // the front row hides parts of the back row, and the frog on the right leaves the view.
    scene.camera.target = {0.3f, 0.4f, -0.5f};
    scene.camera.distance = 2.3f;
    scene.camera.height = 0.35f;
    scene.camera.start_degrees = -20;
    scene.camera.degrees_per_frame = 5;
    scene.camera.fovy_radians = 45.0f * kPi / 180.0f;
    scene.camera.z_near = 0.05f;
    scene.camera.z_far = 30;
    return scene;
}

Scene make_model_scene(LoadedModel model, float degrees_per_frame) {
    Scene scene;
    scene.name = model.name;
    const Mat4 standing = standing_transform(model, 1.0f);
    const Bounds b = transformed_bounds(model.rest, standing);
    SceneInstance instance;
    instance.object_to_world = standing;
    instance.name = std::filesystem::path(model.name).stem().string() + "#0";
    scene.models.push_back(std::move(model));
    scene.instances.push_back(std::move(instance));
    add_ground(scene, 3.0f);
    // As orbit_sequence: far enough that the bounding sphere fits in the vertical field of view.
    const float radius = b.radius();
    const float distance = radius / std::sin(0.5f * scene.camera.fovy_radians) * 1.2f;
    scene.camera.target = b.center();
    scene.camera.distance = distance * std::cos(30.0f * kPi / 180.0f);
    scene.camera.height = distance * std::sin(30.0f * kPi / 180.0f);
    scene.camera.start_degrees = 0;
    scene.camera.degrees_per_frame = degrees_per_frame;
    scene.camera.z_near = std::max(1e-3f, 0.5f * (distance - radius));
    scene.camera.z_far = 2 * (distance + radius) + 6.0f;  // the ground quad reaches 3 units out
    return scene;
}

Scene make_city_scene(Scheme scheme, const CityParams& params) {
    check_range("city blocks_x", params.blocks_x, 1, 64);
    check_range("city blocks_z", params.blocks_z, 1, 64);
    check_range("city block_size", params.block_size, 0.5, 1000);
    check_range("city street_width", params.street_width, 0.5, 1000);
    check_range("city min_height", params.min_height, 0.01, 10000);
    check_range("city max_height", params.max_height, params.min_height, 10000);
    check_range("city characters", params.characters, 0, 5000);
    check_range("city rigid_fraction", params.rigid_fraction, 0, 1);
    check_range("city walking_fraction", params.walking_fraction, 0, 1);
    check_range("city walk_seconds", params.walk_seconds, 0, 3600);
    check_range("city phases", params.phases, 1, 64);
    check_range("city camera_street", params.camera_street, -1, params.blocks_x);

    Scene scene;
    scene.name = "city";
    load_characters(scene, scheme);
    Mat4 standing[2];
    float reach[2];
    character_shapes(scene, standing, reach);
    Rng rng(params.seed);

    // Streets 0..blocks of each axis and blocks between them, the grid centred on the origin.
    const float B = params.block_size, S = params.street_width, P = B + S;
    const float width_x = params.blocks_x * B + (params.blocks_x + 1) * S;
    const float width_z = params.blocks_z * B + (params.blocks_z + 1) * S;
    const float x0 = -0.5f * width_x, z0 = -0.5f * width_z;
    std::vector<Rect> buildings;
    for (int j = 0; j < params.blocks_z; ++j)
        for (int i = 0; i < params.blocks_x; ++i) {
            const Rect r{x0 + i * P + S, z0 + j * P + S, x0 + (i + 1) * P, z0 + (j + 1) * P};
            const float h = rng.uniform(params.min_height, params.max_height);
            add_box(scene, "building#" + std::to_string(buildings.size()), {r.x0, 0, r.z0}, {r.x1, h, r.z1});
            buildings.push_back(r);
        }
    const float ground_half = 0.5f * std::max(width_x, width_z) + 2.0f;
    add_ground(scene, ground_half);

    // The camera walks the middle of z street `street` towards -z; nothing stands in its corridor.
    const int street = params.camera_street >= 0 ? params.camera_street : params.blocks_x / 2;
    const float camera_x = x0 + street * P + 0.5f * S;
    const float corridor = 0.3f;  // half width of the camera's corridor (characters keep their reach + 0.1 more)
    scene.camera.walk = true;
    scene.camera.walk_start = {camera_x, 0.8f, z0 + width_z - 0.5f * S};
    scene.camera.walk_step = {0, 0, -0.15f};
    scene.camera.walk_direction = {0, -0.08f, -1};
    scene.camera.fovy_radians = 60.0f * kPi / 180.0f;
    scene.camera.z_near = 0.05f;
    scene.camera.z_far = 1.5f * std::max(width_x, width_z) + 10.0f;
    scene.camera.distance = 0.25f * std::min(width_x, width_z);  // a typical viewing distance
    scene.camera.height = 0;
    scene.camera.target = scene.camera.walk_start + scene.camera.walk_direction;

    // Characters: a random street (z streets run along z at x street columns, x streets along
    // x), a random point on it; walkers move along the street, so they keep its clearance.
    std::vector<Character> placed;
    SpacingGrid spacing(x0, z0, width_x, width_z, std::max(reach[0], reach[1]));
    for (int k = 0; k < params.characters; ++k) {
        const std::size_t model = static_cast<std::size_t>(k % 2);
        const float r = reach[model];
        bool done = false;
        for (int attempt = 0; attempt < 400 && !done; ++attempt) {
            // A fifth of the characters in the camera's street (beside its corridor), so the
            // street the camera walks is not empty; the others in any street.
            const bool in_camera_street = rng.below(5) == 0;
            const bool along_z = in_camera_street || rng.below(2) == 0;
            const int index =
                in_camera_street ? street : rng.below(along_z ? params.blocks_x + 1 : params.blocks_z + 1);
            const float lateral = rng.uniform(-0.5f * S, 0.5f * S);
            const float along = rng.uniform(0, along_z ? width_z : width_x);
            const bool walking = rng.uniform() < params.walking_fraction;
            const float speed = rng.uniform(0.3f, 0.7f) * (rng.below(2) == 0 ? 1.0f : -1.0f);
            const bool deforms = !(rng.uniform() < params.rigid_fraction);
            const float offset = kPhaseSeconds * static_cast<float>(rng.below(params.phases));
            const float yaw_random = rng.uniform(0, 360);
            Character c;
            c.model = model;
            c.position = along_z ? Vec3{x0 + index * P + 0.5f * S + lateral, 0, z0 + along}
                                 : Vec3{x0 + along, 0, z0 + index * P + 0.5f * S + lateral};
            c.velocity = walking ? (along_z ? Vec3{0, 0, speed} : Vec3{speed, 0, 0}) : Vec3{};
            // Model space faces +z; rotation_y(a) turns +z to (sin a, 0, cos a).
            c.yaw_degrees = walking ? std::atan2(c.velocity.x, c.velocity.z) * 180.0f / kPi : yaw_random;
            c.deforms = deforms;
            c.time_offset = offset;
            // The path over [0, walk_seconds] (a point for a standing character) as a rectangle.
            const Vec3 end = c.position + c.velocity * (walking ? params.walk_seconds : 0.0f);
            const Rect path{std::min(c.position.x, end.x), std::min(c.position.z, end.z), std::max(c.position.x, end.x),
                            std::max(c.position.z, end.z)};
            const float grow = r + kClearance;
            auto overlaps = [&](const Rect& a, float g) {
                return path.x1 > a.x0 - g && path.x0 < a.x1 + g && path.z1 > a.z0 - g && path.z0 < a.z1 + g;
            };
            bool ok = path.x0 - grow >= x0 && path.x1 + grow <= x0 + width_x && path.z0 - grow >= z0 &&
                      path.z1 + grow <= z0 + width_z;
            for (std::size_t b = 0; ok && b < buildings.size(); ++b) ok = !overlaps(buildings[b], grow);
            if (ok) ok = !overlaps(Rect{camera_x - corridor, z0, camera_x + corridor, z0 + width_z}, grow);
            // Start positions apart (walkers may meet later: harmless).
            if (ok) ok = spacing.clear(c.position, r);
            if (!ok) continue;
            placed.push_back(c);
            spacing.add(c.position, r);
            done = true;
        }
        if (!done)
            throw Error("city: no room for " + std::to_string(params.characters) + " characters (placed " +
                        std::to_string(placed.size()) + "; use more blocks or wider streets)");
    }
    add_characters(scene, placed, standing);
    scene.displacement = make_procedural_displacement(512, kDefaultSceneDisplaceScale);
    scene.displacement_name = "procedural";
    return scene;
}

Scene make_building_scene(Scheme scheme, const BuildingParams& params) {
    check_range("building rooms_x", params.rooms_x, 1, 16);
    check_range("building rooms_z", params.rooms_z, 1, 16);
    check_range("building room_size", params.room_size, 3, 100);
    check_range("building wall_height", params.wall_height, 2.2, 20);
    check_range("building wall_thickness", params.wall_thickness, 0.05, 1);
    check_range("building characters_per_room", params.characters_per_room, 0, 64);

    Scene scene;
    scene.name = "building";
    load_characters(scene, scheme);
    Mat4 standing[2];
    float reach[2];
    character_shapes(scene, standing, reach);
    Rng rng(params.seed);

    const int nx = params.rooms_x, nz = params.rooms_z;
    const float R = params.room_size, t = params.wall_thickness, H = params.wall_height;
    const float h = 0.5f * t;
    const float floor_bottom = -0.1f, floor_top = -0.002f, top = H + 0.1f;
    const float xmin = -0.5f * nx * R, zmin = -0.5f * nz * R;
    auto wall_x = [&](int k) { return xmin + k * R; };  // x of wall line k (0..nx)
    auto wall_z = [&](int l) { return zmin + l * R; };
    auto room = [&](int i, int j) {
        return static_cast<std::size_t>(j) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i);
    };

    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i) {
            SceneCell cell;
            cell.name = "room#" + std::to_string(room(i, j));
            cell.box = {{wall_x(i), floor_bottom, wall_z(j)}, {wall_x(i + 1), top, wall_z(j + 1)}};
            scene.cells.push_back(std::move(cell));
        }
    auto add_to_cells = [&](std::initializer_list<std::pair<int, int>> rooms) {
        for (auto [i, j] : rooms)
            if (i >= 0 && i < nx && j >= 0 && j < nz)
                scene.cells[room(i, j)].environment.push_back(scene.environment.size() - 1);
    };
    int wall_pieces = 0;
    auto add_wall_box = [&](Vec3 lo, Vec3 hi, std::initializer_list<std::pair<int, int>> rooms) {
        add_box(scene, "wall#" + std::to_string(wall_pieces++), lo, hi);
        add_to_cells(rooms);
    };
    // Floors and ceilings between the walls' faces.
    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i) {
            const Vec3 lo{wall_x(i) + h, 0, wall_z(j) + h}, hi{wall_x(i + 1) - h, 0, wall_z(j + 1) - h};
            add_box(scene, "floor#" + std::to_string(room(i, j)), {lo.x, floor_bottom, lo.z}, {hi.x, floor_top, hi.z});
            add_to_cells({{i, j}});
            add_box(scene, "ceiling#" + std::to_string(room(i, j)), {lo.x, H, lo.z}, {hi.x, top, hi.z});
            add_to_cells({{i, j}});
        }
    // Posts at the wall junctions.
    for (int l = 0; l <= nz; ++l)
        for (int k = 0; k <= nx; ++k)
            add_wall_box({wall_x(k) - h, floor_bottom, wall_z(l) - h}, {wall_x(k) + h, top, wall_z(l) + h},
                         {{k - 1, l - 1}, {k, l - 1}, {k - 1, l}, {k, l}});
    struct Opening {
        bool any;
        float y0, y1;  // height range; the opening is 1 (door) or 1.2 (window) wide, centred
        float width;
    };
    const Opening door{true, floor_top, 2.0f, 1.0f}, window{true, 1.0f, 1.8f, 1.2f}, none{false, 0, 0, 0};
    // One wall segment between two posts, along axis x (along_x) or z, with an opening: the boxes
    // around the opening, and the portal between the rooms a (lower coordinate side) and b.
    auto add_segment = [&](bool along_x, float line, float s0, float s1, const Opening& o, std::pair<int, int> a,
                           std::pair<int, int> b) {
        auto box = [&](float u0, float u1, float y0, float y1) {
            if (!(u1 > u0) || !(y1 > y0)) return;
            if (along_x)
                add_wall_box({u0, y0, line - h}, {u1, y1, line + h}, {a, b});
            else
                add_wall_box({line - h, y0, u0}, {line + h, y1, u1}, {a, b});
        };
        if (!o.any) {
            box(s0, s1, floor_bottom, top);
            return;
        }
        const float c = 0.5f * (s0 + s1), u0 = c - 0.5f * o.width, u1 = c + 0.5f * o.width;
        box(s0, u0, floor_bottom, top);
        box(u1, s1, floor_bottom, top);
        box(u0, u1, floor_bottom, o.y0);
        box(u0, u1, o.y1, top);
        ScenePortal portal;
        portal.cell_a = room(a.first, a.second);
        portal.cell_b = room(b.first, b.second);
        auto point = [&](float u, float y) { return along_x ? Vec3{u, y, line} : Vec3{line, y, u}; };
        portal.corners[0] = point(u0, o.y0);
        portal.corners[1] = point(u1, o.y0);
        portal.corners[2] = point(u1, o.y1);
        portal.corners[3] = point(u0, o.y1);
        // Counter-clockwise seen from cell_a: the normal points towards a (the lower side).
        const Vec3 n = cross(portal.corners[1] - portal.corners[0], portal.corners[2] - portal.corners[0]);
        if ((along_x ? n.z : n.x) > 0) std::swap(portal.corners[1], portal.corners[3]);
        scene.portals.push_back(portal);
    };
    // Walls of constant z (line l), one segment per column: doors inside the building.
    for (int l = 0; l <= nz; ++l)
        for (int i = 0; i < nx; ++i) {
            const bool inner = l > 0 && l < nz;
            add_segment(true, wall_z(l), wall_x(i) + h, wall_x(i + 1) - h, inner ? door : none, {i, l - 1}, {i, l});
        }
    // Walls of constant x (line k), one segment per row: doors and windows in turn inside.
    for (int k = 0; k <= nx; ++k)
        for (int j = 0; j < nz; ++j) {
            const bool inner = k > 0 && k < nx;
            add_segment(false, wall_x(k), wall_z(j) + h, wall_z(j + 1) - h,
                        inner ? ((j + k) % 2 == 0 ? door : window) : none, {k - 1, j}, {k, j});
        }

    // The camera walks the middle column from its south room (largest z) north, through the
    // doors, crossing the column in 60 frames.
    const int column = nx / 2;
    const float camera_x = wall_x(column) + 0.5f * R;
    const float corridor = 0.6f;
    const float z_start = wall_z(nz) - 0.2f * R, z_end = wall_z(0) + 0.2f * R;
    scene.camera.walk = true;
    scene.camera.walk_start = {camera_x, 0.9f, z_start};
    scene.camera.walk_step = {0, 0, (z_end - z_start) / 60.0f};
    scene.camera.walk_direction = {0, -0.05f, -1};
    scene.camera.fovy_radians = 60.0f * kPi / 180.0f;
    scene.camera.z_near = 0.05f;
    scene.camera.z_far = std::hypot(nx * R, nz * R) + 5.0f;
    scene.camera.distance = 0.5f * R;
    scene.camera.height = 0;
    scene.camera.target = scene.camera.walk_start + scene.camera.walk_direction;

    // Characters: rejection sampling in each room, away from the walls (and the doorways'
    // thresholds, which are inside the walls' lines), the camera's corridor and each other.
    std::vector<Character> placed;
    std::vector<float> placed_reach;
    std::vector<std::size_t> placed_room;
    int count = 0;
    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i) {
            const std::size_t room_first = placed.size();  // other rooms' characters are behind walls
            for (int n = 0; n < params.characters_per_room; ++n, ++count) {
                const std::size_t model = static_cast<std::size_t>(count % 2);
                const float r = reach[model], grow = r + kClearance;
                for (int attempt = 0; attempt < 200; ++attempt) {
                    Character c;
                    c.model = model;
                    c.position = {rng.uniform(wall_x(i) + h + grow, wall_x(i + 1) - h - grow), 0,
                                  rng.uniform(wall_z(j) + h + grow, wall_z(j + 1) - h - grow)};
                    c.yaw_degrees = rng.uniform(0, 360);
                    c.velocity = {};
                    c.deforms = count % 3 != 2;
                    c.time_offset = kPhaseSeconds * static_cast<float>(rng.below(6));
                    bool ok = c.position.x > wall_x(i) + h + grow && c.position.x < wall_x(i + 1) - h - grow &&
                              c.position.z > wall_z(j) + h + grow && c.position.z < wall_z(j + 1) - h - grow;
                    if (ok) ok = std::fabs(c.position.x - camera_x) >= corridor + grow;
                    for (std::size_t o = room_first; ok && o < placed.size(); ++o) {
                        const float g = r + placed_reach[o];
                        ok = std::fabs(placed[o].position.x - c.position.x) >= g ||
                             std::fabs(placed[o].position.z - c.position.z) >= g;
                    }
                    if (!ok) continue;
                    placed.push_back(c);
                    placed_reach.push_back(r);
                    placed_room.push_back(room(i, j));
                    break;
                }
            }
        }
    add_characters(scene, placed, standing);
    for (std::size_t k = 0; k < placed_room.size(); ++k) scene.cells[placed_room[k]].instances.push_back(k);
    scene.displacement = make_procedural_displacement(512, kDefaultSceneDisplaceScale);
    scene.displacement_name = "procedural";
    return scene;
}

Scene make_builtin_scene(const std::string& name, Scheme scheme) {
    if (name == "default") return make_default_scene(scheme);
    if (name == "city") return make_city_scene(scheme);
    if (name == "building") return make_building_scene(scheme);
    throw Error("unknown scene " + quote_input(name) + " (default, city or building)");
}

}  // namespace patchcull
