// Scenes for the renderer (patchcull/import/default_scene.h): the built-in default scene in the spirit
// of Niessner & Loop, Fig. 1 (c) (animated characters among triangle occluders), and one-model scenes.
#include "patchcull/import/default_scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "patchcull/core/error.h"
#include "scene_builder.h"

namespace patchcull {
namespace detail {

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

Mat4 rotation_y(float degrees) {
    const float a = degrees * kPi / 180.0f;
    Mat4 m;
    m.at(0, 0) = std::cos(a);
    m.at(0, 2) = std::sin(a);
    m.at(2, 0) = -std::sin(a);
    m.at(2, 2) = std::cos(a);
    return m;
}

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

Mat4 standing_transform(const LoadedModel& model, float height) {
    const Mat4 up = model.subdiv ? Mat4{} : teapot_to_y_up();
    const Bounds b = transformed_bounds(model.rest, up);
    const float extent = b.max.y - b.min.y;
    if (!(extent > 0)) throw Error(model.name + ": the model has no height (all control points at one y)");
    const float s = height / extent;
    const Vec3 base{0.5f * (b.min.x + b.max.x), b.min.y, 0.5f * (b.min.z + b.max.z)};
    return scaling(s) * translation(-base) * up;
}

void add_triangles(Scene& scene, std::string name, const std::vector<Vec3>& vertices,
                   const std::vector<std::uint32_t>& indices, bool one_sided) {
    const auto base = static_cast<std::uint32_t>(scene.occluder_vertices.size());
    EnvironmentObject object;
    object.name = std::move(name);
    object.first_triangle = static_cast<std::uint32_t>(scene.occluder_indices.size() / 3);
    object.triangle_count = static_cast<std::uint32_t>(indices.size() / 3);
    object.one_sided = one_sided;
    scene.occluder_vertices.insert(scene.occluder_vertices.end(), vertices.begin(), vertices.end());
    for (std::uint32_t i : indices) scene.occluder_indices.push_back(base + i);
    scene.environment.push_back(std::move(object));
}

void add_box(Scene& scene, std::string name, Vec3 lo, Vec3 hi) {
    std::vector<Vec3> vertices;
    for (int i = 0; i < 8; ++i)
        vertices.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
    // Faces as corner quads (bit 0 = x, bit 1 = y, bit 2 = z), each counter-clockwise seen from
    // outside: -x, +x, -y, +y, -z, +z (tests check the signed volume is the box's).
    const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    std::vector<std::uint32_t> indices;
    for (const auto& q : quads)
        for (int k : {0, 1, 2, 0, 2, 3}) indices.push_back(q[k]);
    add_triangles(scene, std::move(name), vertices, indices, true);
}

void add_quad(Scene& scene, std::string name, const Vec3 corners[4], bool one_sided) {
    add_triangles(scene, std::move(name), {corners[0], corners[1], corners[2], corners[3]}, {0, 1, 2, 0, 2, 3},
                  one_sided);
}

void add_ground(Scene& scene, float half_size) {
    const float y = -0.002f;
    const float h = half_size;
    // Counter-clockwise seen from +y.
    const Vec3 corners[4] = {{-h, y, -h}, {-h, y, h}, {h, y, h}, {h, y, -h}};
    add_quad(scene, "ground", corners, true);
}

void load_characters(Scene& scene, Scheme scheme) {
    scene.models.push_back(load_model(shipped_model_path("bigguy.obj"), scheme, 0));
    scene.models.push_back(load_model(shipped_model_path("monsterfrog.obj"), scheme, 0));
}

float animated_reach(const LoadedModel& model, const Mat4& standing, const AnimationParams& animation, int samples) {
    float reach = 0;
    auto measure = [&](const PatchFrame& frame) {
        for (const BezierPatch& p : frame.patches)
            for (const Vec4& c : p.cp) {
                const Vec3 q = cartesian(standing * c);
                reach = std::max(reach, std::hypot(q.x, q.z));
            }
    };
    measure(model.rest);
    if (!model.subdiv) return reach;
    std::vector<Vec3> positions;
    PatchFrame frame;
    for (int k = 0; k < samples; ++k) {
        animate(model.subdiv->mesh.positions, animation.period_seconds * static_cast<float>(k) / static_cast<float>(samples),
                animation, positions);
        evaluate_frame(model, positions, frame);
        measure(frame);
    }
    return reach;
}

}  // namespace detail

using namespace detail;

void add_environment_object(Scene& scene, std::string name, const std::vector<Vec3>& vertices,
                            const std::vector<std::uint32_t>& indices, bool one_sided) {
    if (indices.size() % 3 != 0) throw Error(name + ": " + std::to_string(indices.size()) + " indices, not whole triangles");
    for (std::uint32_t i : indices)
        if (i >= vertices.size()) throw Error(name + ": index " + std::to_string(i) + " beyond the " + std::to_string(vertices.size()) + " vertices");
    add_triangles(scene, std::move(name), vertices, indices, one_sided);
}

void add_environment_box(Scene& scene, std::string name, Vec3 lo, Vec3 hi) { add_box(scene, std::move(name), lo, hi); }

bool instance_mirrors(const SceneInstance& instance) {
    const Mat4& m = instance.object_to_world;
    auto a = [&](int r, int c) { return static_cast<double>(m.at(r, c)); };
    const double det = a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) -
                       a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) +
                       a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
    return det < 0;
}

Mat4 instance_to_frame(const SceneInstance& instance, float time_seconds, DVec3 frame_origin) {
    // translation(d) * M adds d * M's w row to each column's xyz: for an affine M the w row is
    // (0, 0, 0, 1), so only column 3 moves. d = origin - frame_origin + v * (t + time_offset),
    // summed in double with column 3 and rounded once.
    Mat4 m = instance.object_to_world;
    const double t = double(time_seconds) + double(instance.time_offset);
    const double d[3] = {instance.origin.x - frame_origin.x + double(instance.velocity.x) * t,
                         instance.origin.y - frame_origin.y + double(instance.velocity.y) * t,
                         instance.origin.z - frame_origin.z + double(instance.velocity.z) * t};
    for (int c = 0; c < 4; ++c) {
        const double w = m.at(3, c);
        if (w == 0) continue;
        for (int r = 0; r < 3; ++r) m.at(r, c) = static_cast<float>(double(m.at(r, c)) + d[r] * w);
    }
    return m;
}

Mat4 instance_to_world(const SceneInstance& instance, float time_seconds) {
    return instance_to_frame(instance, time_seconds, {});
}

DVec3 scene_frame_near(DVec3 eye) {
    if (std::fabs(eye.x) <= kSceneWorldFrame && std::fabs(eye.y) <= kSceneWorldFrame && std::fabs(eye.z) <= kSceneWorldFrame)
        return {};
    auto snap = [](double x) { return std::nearbyint(x / kSceneFrameGrid) * kSceneFrameGrid; };
    return {snap(eye.x), snap(eye.y), snap(eye.z)};
}

void rebase_scene(const Scene& world, DVec3 origin, Scene& frame) {
    // Frame-relative floats: world coordinates (double) minus origin, rounded once.
    const DVec3 shift = world.frame_origin - origin;
    auto moved = [&](Vec3 v) { return to_float(to_double(v) + shift); };
    frame.name = world.name;
    frame.instances = world.instances;
    frame.environment = world.environment;
    frame.occluder_indices = world.occluder_indices;
    frame.occluder_world = world.occluder_world;
    frame.occluder_vertices.resize(world.occluder_vertices.size());
    for (std::size_t i = 0; i < world.occluder_vertices.size(); ++i)
        frame.occluder_vertices[i] = world.occluder_world.empty() ? moved(world.occluder_vertices[i])
                                                                  : to_float(world.occluder_world[i] - origin);
    frame.animation = world.animation;
    frame.displacement = world.displacement;
    frame.displacement_name = world.displacement_name;
    frame.camera = world.camera;
    frame.cells = world.cells;
    frame.cell_world = world.cell_world;
    for (std::size_t i = 0; i < frame.cells.size(); ++i) {
        Bounds& box = frame.cells[i].box;
        box = world.cell_world.empty() ? Bounds{moved(box.min), moved(box.max)}
                                       : Bounds{to_float(world.cell_world[i][0] - origin), to_float(world.cell_world[i][1] - origin)};
    }
    frame.portals = world.portals;
    frame.portal_world = world.portal_world;
    for (std::size_t i = 0; i < frame.portals.size(); ++i)
        for (int k = 0; k < 4; ++k) {
            Vec3& c = frame.portals[i].corners[k];
            c = world.portal_world.empty() ? moved(c) : to_float(world.portal_world[i][std::size_t(k)] - origin);
        }
    frame.frame_origin = origin;
}

std::size_t Scene::patch_count() const {
    std::size_t n = 0;
    for (const SceneInstance& instance : instances) n += models.at(instance.model).rest.patches.size();
    return n;
}

std::vector<WorldCamera> Scene::world_camera_path(int frames, float aspect) const {
    std::vector<WorldCamera> cameras;
    const DVec3 o = camera.origin;
    for (int f = 0; f < frames; ++f) {
        WorldCamera cam;
        if (camera.walk) {
            cam.eye = o + to_double(camera.walk_start) + DVec3{double(camera.walk_step.x) * f, double(camera.walk_step.y) * f,
                                                               double(camera.walk_step.z) * f};
            cam.target = cam.eye + to_double(camera.walk_direction);
        } else {
            const double a = (double(camera.start_degrees) + double(f) * double(camera.degrees_per_frame)) *
                             (3.14159265358979323846 / 180.0);
            cam.target = o + to_double(camera.target);
            cam.eye = cam.target + DVec3{double(camera.distance) * std::sin(a), double(camera.height),
                                         double(camera.distance) * std::cos(a)};
        }
        cam.up = {0, 1, 0};
        cam.fovy_radians = camera.fovy_radians;
        cam.aspect = aspect;
        cam.z_near = camera.z_near;
        cam.z_far = camera.z_far;
        cameras.push_back(cam);
    }
    return cameras;
}

std::vector<Camera> Scene::camera_path(int frames, float aspect) const {
    if (camera.origin.x != frame_origin.x || camera.origin.y != frame_origin.y || camera.origin.z != frame_origin.z) {
        std::vector<Camera> cameras;
        for (const WorldCamera& w : world_camera_path(frames, aspect)) cameras.push_back(w.local(frame_origin));
        return cameras;
    }
    std::vector<Camera> cameras;
    for (int f = 0; f < frames; ++f) {
        Camera cam;
        if (camera.walk) {
            cam.eye = camera.walk_start + camera.walk_step * static_cast<float>(f);
            cam.target = cam.eye + camera.walk_direction;
        } else {
            const float a = (camera.start_degrees + f * camera.degrees_per_frame) * kPi / 180.0f;
            cam.eye = camera.target + Vec3{camera.distance * std::sin(a), camera.height, camera.distance * std::cos(a)};
            cam.target = camera.target;
        }
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

// Mirrored instances (instance_mirrors): M with det M < 0 maps du x dv to cof(M) (du x dv) =
// det(M) M^-T (du x dv), which points into the mirrored solid (the outward normal of the image is
// along M^-T n). Posing the transposed patch P'(u, v) = P(v, u) swaps the derivatives, du' = dv and
// dv' = du, so du' x dv' = -(du x dv) and the world normal is |det M| M^-T n: outward again. The
// transposition only reorders control points (exact); for a world point M P(v, u) and an eye e,
// (e - M p) . N' = |det M| (M^-1 e - p) . n, so the one-sided fragment test of the world patch
// is the model-space test with the eye moved into model space (what the patch clusters test).
// Transposed, with everything that goes with the patch:
// - control points: cp'[4j + i] = cp[4i + j];
// - ACC tangent patches: du'(u, v) = dv(v, u) and dv'(u, v) = du(v, u), i.e.
//   du'[3j + i] = dv[4i + j] (i < 3, j < 4) and dv'[4j + i] = du[3i + j] (i < 4, j < 3);
// - corner texcoords (corners (0,0), (1,0), (0,1), (1,1)): corners 1 and 2 swap;
// - the displacement range (over the corners' texcoord box) and the depth are per patch: unchanged.

ScenePoser::ScenePoser(const Scene& scene) : scene_(&scene) {
    if (scene.displacement.empty()) return;
    for (const SceneInstance& instance : scene.instances) {
        const PatchFrame& rest = scene.models.at(instance.model).rest;
        const bool mirrored = instance_mirrors(instance);
        for (const PatchInfo& info : rest.info) {
            if (mirrored)
                texcoords_.push_back({info.uv[0], info.uv[2], info.uv[1], info.uv[3]});
            else
                texcoords_.push_back({info.uv[0], info.uv[1], info.uv[2], info.uv[3]});
            ranges_.push_back(instance.displaced ? scene.displacement.patch_range(info.uv) : DisplacementRange{});
        }
    }
}

void ScenePoser::group_instances(float time_seconds) {
    const Scene& scene = *scene_;
    const std::size_t n = scene.instances.size();
    order_.resize(n);
    times_.resize(n);
    const float rest_time = -std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
        const SceneInstance& instance = scene.instances[i];
        const bool animated = instance.deforms && scene.models.at(instance.model).subdiv.has_value();
        times_[i] = animated ? time_seconds + instance.time_offset : rest_time;
        order_[i] = i;
    }
    std::sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) {
        const std::size_t ma = scene.instances[a].model, mb = scene.instances[b].model;
        if (ma != mb) return ma < mb;
        if (times_[a] != times_[b]) return times_[a] < times_[b];
        return a < b;
    });
}

const std::vector<PoseModelTables>& ScenePoser::gpu_tables() {
    const Scene& scene = *scene_;
    if (gpu_tables_.size() == scene.models.size()) return gpu_tables_;
    std::vector<PoseModelTables> tables(scene.models.size());
    identity_tables_.assign(scene.models.size(), PointStencils{});
    for (std::size_t m = 0; m < scene.models.size(); ++m) {
        const LoadedModel& model = scene.models[m];
        if (model.split_levels > 0)
            throw Error(model.name + ": posing by stencils needs unsplit patches (--split " +
                        std::to_string(model.split_levels) + " splits them after the stencils)");
        PoseModelTables& t = tables[m];
        for (const PatchInfo& info : model.rest.info) t.tangent_index.push_back(info.tangent_index);
        if (model.subdiv) {
            t.patch_points = &model.subdiv->patch_points;
            t.tangent_points = &model.subdiv->tangent_points;
            t.vertex_count = static_cast<std::uint32_t>(model.subdiv->mesh.positions.size());
            continue;
        }
        // No control mesh: the rest control points are the "vertices", each row one of them
        // with weight 1 (1 * v is exact in double, and so is its rounding back to float).
        PointStencils& identity = identity_tables_[m];
        std::uint32_t v = 0;
        for (const BezierPatch& patch : model.rest.patches)
            for (const Vec4& c : patch.cp) {
                if (c.w != 1.0f)
                    throw Error(model.name + ": posing by stencils needs control points with w = 1 (a rational patch)");
                identity.add_row({{v++, 1.0f}});
            }
        t.patch_points = &identity;
        t.tangent_points = &no_tangents_;
        t.vertex_count = v;
        for (std::int32_t index : t.tangent_index)
            if (index >= 0) throw Error(model.name + ": tangent patches without a control mesh");
    }
    gpu_tables_ = std::move(tables);
    return gpu_tables_;
}

const PoseMeshes& ScenePoser::gpu_meshes(float time_seconds) {
    const Scene& scene = *scene_;
    const std::size_t n = scene.instances.size();
    group_instances(time_seconds);
    meshes_.vertices.clear();
    meshes_.first_vertex.resize(n);
    meshes_.to_world.resize(n);
    meshes_.mirrored.resize(n);
    const float rest_time = -std::numeric_limits<float>::infinity();
    bool have_group = false;
    std::size_t group_model = 0, group_first = 0;
    float group_time = 0;
    for (std::size_t i : order_) {
        const SceneInstance& instance = scene.instances[i];
        const LoadedModel& model = scene.models.at(instance.model);
        if (!have_group || group_model != instance.model || !(group_time == times_[i])) {
            group_first = meshes_.vertices.size();
            if (!model.subdiv) {
                for (const BezierPatch& patch : model.rest.patches)
                    for (const Vec4& c : patch.cp) meshes_.vertices.push_back({c.x, c.y, c.z});
            } else if (times_[i] == rest_time) {
                const std::vector<Vec3>& rest = model.subdiv->mesh.positions;
                meshes_.vertices.insert(meshes_.vertices.end(), rest.begin(), rest.end());
            } else {
                animate(model.subdiv->mesh.positions, times_[i], scene.animation, positions_);
                meshes_.vertices.insert(meshes_.vertices.end(), positions_.begin(), positions_.end());
            }
            have_group = true;
            group_model = instance.model;
            group_time = times_[i];
        }
        meshes_.first_vertex[i] = group_first;
        meshes_.to_world[i] = instance_to_frame(instance, time_seconds, scene.frame_origin);
        meshes_.mirrored[i] = instance_mirrors(instance) ? 1 : 0;
    }
    return meshes_;
}

const std::vector<BezierPatch>& ScenePoser::pose(float time_seconds) {
    const Scene& scene = *scene_;
    const std::size_t n = scene.instances.size();
    // Each instance's first patch and first tangent entry (recomputed per call: cheap, and the
    // scene may have been edited since the poser was made).
    tangent_counts_.assign(scene.models.size(), 0);
    for (std::size_t m = 0; m < scene.models.size(); ++m)
        for (const PatchInfo& info : scene.models[m].rest.info) tangent_counts_[m] += info.tangent_index >= 0 ? 1 : 0;
    first_patch_.resize(n);
    first_tangent_.resize(n);
    std::size_t total = 0, total_tangents = 0;
    for (std::size_t i = 0; i < n; ++i) {
        first_patch_[i] = total;
        first_tangent_[i] = total_tangents;
        total += scene.models.at(scene.instances[i].model).rest.patches.size();
        total_tangents += tangent_counts_[scene.instances[i].model];
    }
    order_.resize(n);
    times_.resize(n);
    patches_.resize(total);
    tangent_index_.assign(total, -1);
    depth_.assign(total, 0);
    tangents_.resize(total_tangents);
    // Group the instances by (model, effective time): each group's frame is evaluated once.
    const float rest_time = -std::numeric_limits<float>::infinity();
    group_instances(time_seconds);
    const PatchFrame* frame = nullptr;
    std::size_t frame_model = 0;
    float frame_time = 0;
    for (std::size_t i : order_) {
        const SceneInstance& instance = scene.instances[i];
        const LoadedModel& model = scene.models.at(instance.model);
        if (!frame || frame_model != instance.model || !(frame_time == times_[i])) {
            if (times_[i] == rest_time) {
                frame = &model.rest;
            } else {
                animate(model.subdiv->mesh.positions, times_[i], scene.animation, positions_);
                evaluate_frame(model, positions_, frame_);
                frame = &frame_;
            }
            frame_model = instance.model;
            frame_time = times_[i];
        }
        const Mat4 to_world = instance_to_frame(instance, time_seconds, scene.frame_origin);
        // Tangent vectors map by the linear part of the affine transform (w = 0).
        auto linear = [&](Vec3 d) {
            const Vec4 m = to_world * Vec4{d.x, d.y, d.z, 0.0f};
            return Vec3{m.x, m.y, m.z};
        };
        const bool mirrored = instance_mirrors(instance);  // transposed (see above ScenePoser::ScenePoser)
        std::size_t next = first_patch_[i];
        std::size_t next_tangent = first_tangent_[i];
        for (std::size_t p = 0; p < frame->patches.size(); ++p) {
            BezierPatch& out = patches_[next];
            const BezierPatch& in = frame->patches[p];
            if (mirrored) {
                for (int j = 0; j < 4; ++j)
                    for (int k = 0; k < 4; ++k) out.cp[4 * j + k] = to_world * in.cp[4 * k + j];
            } else {
                for (int k = 0; k < kPatchPoints; ++k) out.cp[k] = to_world * in.cp[k];
            }
            depth_[next] = frame->info[p].depth;
            const std::int32_t t = frame->info[p].tangent_index;
            if (t >= 0) {
                TangentPatches& mapped = tangents_[next_tangent];
                const TangentPatches& source = frame->tangents[static_cast<std::size_t>(t)];
                if (mirrored) {
                    for (int j = 0; j < 4; ++j)
                        for (int k = 0; k < 3; ++k) mapped.du[3 * j + k] = linear(source.dv[4 * k + j]);
                    for (int j = 0; j < 3; ++j)
                        for (int k = 0; k < 4; ++k) mapped.dv[4 * j + k] = linear(source.du[3 * k + j]);
                } else {
                    for (int k = 0; k < 12; ++k) mapped.du[k] = linear(source.du[k]), mapped.dv[k] = linear(source.dv[k]);
                }
                tangent_index_[next] = static_cast<std::int32_t>(next_tangent);
                ++next_tangent;
            }
            ++next;
        }
    }
    return patches_;
}

}  // namespace patchcull
