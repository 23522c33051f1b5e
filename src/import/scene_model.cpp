// The scene data model (patchcull/import/scene_model.h): instance transforms, frames near the
// camera (scene_frame_near, rebase_scene) and camera paths.
#include "patchcull/import/scene_model.h"

#include <cmath>

#include "scene_builder.h"

namespace patchcull {

using detail::kPi;

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
    if (std::fabs(eye.x) <= kSceneWorldFrame && std::fabs(eye.y) <= kSceneWorldFrame &&
        std::fabs(eye.z) <= kSceneWorldFrame)
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
        box = world.cell_world.empty()
                  ? Bounds{moved(box.min), moved(box.max)}
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

Scene rebase_scene_in_place(Scene& scene, DVec3 origin) {
    std::vector<LoadedModel> models = std::move(scene.models);
    Scene world = scene;  // the placements, without the models
    scene.models = std::move(models);
    rebase_scene(world, origin, scene);
    return world;
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
            cam.eye =
                o + to_double(camera.walk_start) +
                DVec3{double(camera.walk_step.x) * f, double(camera.walk_step.y) * f, double(camera.walk_step.z) * f};
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

}  // namespace patchcull
