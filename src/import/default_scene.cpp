// Scenes for the renderer (patchcull/default_scene.h): the built-in default scene in the spirit
// of seed 000 Fig. 1 (c) (animated characters among triangle occluders), and one-model scenes.
#include "patchcull/default_scene.h"

#include <algorithm>
#include <cmath>

#include "patchcull/error.h"

namespace patchcull {
namespace {

constexpr float kPi = 3.14159265358979f;

Mat4 translation(Vec3 t) {
    Mat4 m;
    m.at(0, 3) = t.x;
    m.at(1, 3) = t.y;
    m.at(2, 3) = t.z;
    return m;
}

Mat4 scaling(float s) {
    Mat4 m;
    m.at(0, 0) = m.at(1, 1) = m.at(2, 2) = s;
    return m;
}

// Rotation about the world y axis by `degrees` (counter-clockwise seen from +y).
Mat4 rotation_y(float degrees) {
    const float a = degrees * kPi / 180.0f;
    Mat4 m;
    m.at(0, 0) = std::cos(a);
    m.at(0, 2) = std::sin(a);
    m.at(2, 0) = -std::sin(a);
    m.at(2, 2) = std::cos(a);
    return m;
}

// The built-in teapot is z-up: (x, y, z) -> (x, z, -y) stands it on the y = 0 plane.
Mat4 teapot_to_y_up() {
    Mat4 m;
    m.at(1, 1) = 0;
    m.at(1, 2) = 1;
    m.at(2, 1) = -1;
    m.at(2, 2) = 0;
    return m;
}

Bounds transformed_bounds(const PatchFrame& frame, const Mat4& m) {
    std::vector<Vec3> points;
    points.reserve(frame.patches.size() * kPatchPoints);
    for (const BezierPatch& p : frame.patches)
        for (const Vec4& c : p.cp) points.push_back(cartesian(m * c));
    return compute_bounds(points);
}

// Object space -> "standing" space: y-up, scaled to height `height`, centred on x = z = 0, feet at
// y = 0 (from the control points at rest, which bound the surface).
Mat4 standing_transform(const LoadedModel& model, float height) {
    const Mat4 up = model.subdiv ? Mat4{} : teapot_to_y_up();
    const Bounds b = transformed_bounds(model.rest, up);
    const float extent = b.max.y - b.min.y;
    if (!(extent > 0)) throw Error(model.name + ": the model has no height (all control points at one y)");
    const float s = height / extent;
    const Vec3 base{0.5f * (b.min.x + b.max.x), b.min.y, 0.5f * (b.min.z + b.max.z)};
    return scaling(s) * translation(-base) * up;
}

// An axis-aligned box [lo, hi] as 12 triangles.
void add_box(Scene& scene, Vec3 lo, Vec3 hi) {
    const auto base = static_cast<std::uint32_t>(scene.occluder_vertices.size());
    for (int i = 0; i < 8; ++i)
        scene.occluder_vertices.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
    // Faces as corner quads (bit 0 = x, bit 1 = y, bit 2 = z); the renderer draws both sides.
    const std::uint32_t quads[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                       {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& q : quads)
        for (int k : {0, 1, 2, 0, 2, 3}) scene.occluder_indices.push_back(base + q[k]);
}

void add_ground(Scene& scene, float half_size) {
    const auto base = static_cast<std::uint32_t>(scene.occluder_vertices.size());
    // Slightly below y = 0, so that feet resting on the ground are not tied with it in depth.
    const float y = -0.002f;
    for (Vec3 p : {Vec3{-half_size, y, -half_size}, Vec3{half_size, y, -half_size}, Vec3{half_size, y, half_size},
                   Vec3{-half_size, y, half_size}})
        scene.occluder_vertices.push_back(p);
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) scene.occluder_indices.push_back(base + i);
}

}  // namespace

std::size_t Scene::patch_count() const {
    std::size_t n = 0;
    for (const SceneInstance& instance : instances) n += models.at(instance.model).rest.patches.size();
    return n;
}

std::vector<Camera> Scene::camera_path(int frames, float aspect) const {
    std::vector<Camera> cameras;
    for (int f = 0; f < frames; ++f) {
        const float a = (camera.start_degrees + f * camera.degrees_per_frame) * kPi / 180.0f;
        Camera cam;
        cam.eye = camera.target + Vec3{camera.distance * std::sin(a), camera.height, camera.distance * std::cos(a)};
        cam.target = camera.target;
        cam.fovy_radians = camera.fovy_radians;
        cam.aspect = aspect;
        cam.z_near = camera.z_near;
        cam.z_far = camera.z_far;
        cameras.push_back(cam);
    }
    return cameras;
}

Scene make_default_scene(Scheme scheme) {
    Scene scene;
    scene.name = "default";
    scene.models.push_back(load_model(shipped_model_path("bigguy.obj"), scheme, 0));
    scene.models.push_back(load_model(shipped_model_path("monsterfrog.obj"), scheme, 0));
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
    for (const Placement& p : placements) {
        const Mat4& standing = p.model == 0 ? bigguy : frog;
        const bool displaced = p.model == 1;  // the frogs
        scene.instances.push_back(
            {p.model, translation(p.position) * rotation_y(p.yaw_degrees) * standing, offset, displaced});
        offset += 0.37f;
    }
    scene.displacement = make_procedural_displacement(512, kDefaultSceneDisplaceScale);
    scene.displacement_name = "procedural";
    add_ground(scene, 6.0f);
    add_box(scene, {-2.6f, 0, 0.75f}, {0.9f, 0.42f, 0.9f});  // low wall in front of the front row
    add_box(scene, {-0.45f, 0, -0.85f}, {-0.2f, 1.5f, -0.6f});  // pillar between the rows
    add_box(scene, {1.0f, 0, -0.75f}, {1.2f, 1.3f, -0.55f});    // a second, thinner pillar
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
    scene.models.push_back(std::move(model));
    scene.instances.push_back({0, standing, 0});
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

ScenePoser::ScenePoser(const Scene& scene) : scene_(&scene) {
    if (scene.displacement.empty()) return;
    for (const SceneInstance& instance : scene.instances) {
        const PatchFrame& rest = scene.models.at(instance.model).rest;
        for (const PatchInfo& info : rest.info) {
            texcoords_.push_back({info.uv[0], info.uv[1], info.uv[2], info.uv[3]});
            ranges_.push_back(instance.displaced ? scene.displacement.patch_range(info.uv) : DisplacementRange{});
        }
    }
}

const std::vector<BezierPatch>& ScenePoser::pose(float time_seconds) {
    const Scene& scene = *scene_;
    patches_.resize(scene.patch_count());
    tangent_index_.assign(scene.patch_count(), -1);
    depth_.assign(scene.patch_count(), 0);
    tangents_.clear();
    std::size_t next = 0;
    for (const SceneInstance& instance : scene.instances) {
        const LoadedModel& model = scene.models.at(instance.model);
        const PatchFrame* frame = &model.rest;
        if (model.subdiv) {
            animate(model.subdiv->mesh.positions, time_seconds + instance.time_offset, scene.animation, positions_);
            evaluate_frame(model, positions_, frame_);
            frame = &frame_;
        }
        // Tangent vectors map by the linear part of the affine object_to_world (w = 0).
        auto linear = [&](Vec3 d) {
            const Vec4 m = instance.object_to_world * Vec4{d.x, d.y, d.z, 0.0f};
            return Vec3{m.x, m.y, m.z};
        };
        for (std::size_t p = 0; p < frame->patches.size(); ++p) {
            BezierPatch& out = patches_[next];
            for (int k = 0; k < kPatchPoints; ++k) out.cp[k] = instance.object_to_world * frame->patches[p].cp[k];
            depth_[next] = frame->info[p].depth;
            const std::int32_t t = frame->info[p].tangent_index;
            if (t >= 0) {
                TangentPatches mapped;
                const TangentPatches& source = frame->tangents[static_cast<std::size_t>(t)];
                for (int k = 0; k < 12; ++k) mapped.du[k] = linear(source.du[k]), mapped.dv[k] = linear(source.dv[k]);
                tangent_index_[next] = static_cast<std::int32_t>(tangents_.size());
                tangents_.push_back(mapped);
            }
            ++next;
        }
    }
    return patches_;
}

}  // namespace patchcull
