// What a scene reaches over a run, and its frame moved to the first camera
// (patchcull/import/scene_file.h: check_scene_motion, place_scene_at_first_camera).
#include "patchcull/import/scene_file.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "number_text.h"
#include "patchcull/core/error.h"
#include "patchcull/import/scene_model.h"

namespace patchcull {
namespace {

using detail::number_text;

// The first coordinate of the points in [lo, hi] (a box) moved by d that lies beyond the limit
// (axis in 0..2, value), or axis -1.
struct Reach {
    int axis = -1;
    double value = 0;
};
Reach beyond_limit(const double lo[3], const double hi[3], const double d[3], double limit, DVec3 centre) {
    const double o[3] = {centre.x, centre.y, centre.z};
    for (int a = 0; a < 3; ++a)
        for (double c : {lo[a] + d[a], hi[a] + d[a]})
            if (!(std::fabs(c - o[a]) <= limit)) return {a, c};
    return {};
}

static_assert(kMaxSceneCoordinate == 536870912.0, "the messages name the limit as 536870912 (2^29)");

// A limit as written in the docs: 536870912 (2^29), 8192.
std::string limit_text(double limit) {
    char text[48];
    std::snprintf(text, sizeof text, "%.0f", limit);
    return text + std::string(limit == kMaxSceneCoordinate ? " (2^29)" : "");
}

[[noreturn]] void motion_fail(const std::string& source, const std::string& path, const std::string& what, Reach r,
                              int frame, double seconds, const std::string& advice) {
    static const char* const axes[3] = {"x", "y", "z"};
    throw Error(printable_line(source + ": " + path + ": " + what + " reaches " + axes[r.axis] + " = " +
                               number_text(r.value) + " at frame " + std::to_string(frame) + " (time " +
                               number_text(seconds) + " s); " + advice));
}

}  // namespace

void check_scene_motion(const Scene& scene, const std::string& source, int frames, double seconds_per_frame,
                        double limit, DVec3 centre) {
    if (frames <= 0) return;
    const int last = frames - 1;
    const bool at_origin = centre.x == 0 && centre.y == 0 && centre.z == 0;
    const std::string advice =
        limit >= kMaxSceneCoordinate && at_origin
            ? "scenes take world coordinates up to " + limit_text(limit)
            : "this command draws a scene in one float frame, at its first camera's grid point (" +
                  number_text(centre.x) + ", " + number_text(centre.y) + ", " + number_text(centre.z) +
                  "), and takes what lies within " + limit_text(limit) + " of it";
    auto beyond = [&](const double lo[3], const double hi[3], const double d[3]) {
        return beyond_limit(lo, hi, d, limit, centre);
    };
    auto seconds = [&](int f) { return double(f) * seconds_per_frame; };
    const DVec3 world = scene.frame_origin;
    // Objects: the placed rest control points' box (in double), moved by velocity x time.
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const SceneInstance& instance = scene.instances[i];
        const Vec3 v = instance.velocity;
        const bool moves = v.x != 0 || v.y != 0 || v.z != 0;
        const Mat4& m = instance.object_to_world;
        double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
        const double o[3] = {instance.origin.x, instance.origin.y, instance.origin.z};
        for (const BezierPatch& patch : scene.models.at(instance.model).rest.patches)
            for (const Vec4& c : patch.cp) {
                const double h[4] = {c.x, c.y, c.z, c.w};
                double w = 0;
                for (int k = 0; k < 4; ++k) w += double(m.at(3, k)) * h[k];
                for (int a = 0; a < 3; ++a) {
                    double x = 0;
                    for (int k = 0; k < 4; ++k) x += double(m.at(a, k)) * h[k];
                    x = x / w + o[a];
                    lo[a] = std::min(lo[a], x);
                    hi[a] = std::max(hi[a], x);
                }
            }
        auto moved = [&](int f) {
            const double t = moves ? seconds(f) + double(instance.time_offset) : 0.0;
            const double d[3] = {double(v.x) * t, double(v.y) * t, double(v.z) * t};
            return beyond(lo, hi, d);
        };
        // The motion is linear: within the limit at the first and the last frame, within it at
        // every frame between.
        if (moved(0).axis < 0 && moved(last).axis < 0) continue;
        for (int f = 0; f <= last; ++f)
            if (const Reach r = moved(f); r.axis >= 0) {
                const std::string path = "objects[" + std::to_string(i) + "]" +
                                         (!moves                                ? ".transform"
                                          : f == 0 && instance.time_offset != 0 ? ".animation.time_offset"
                                                                                : ".animation.velocity");
                motion_fail(
                    source, path,
                    std::string(moves ? "the moving" : "the placed") + " model (" + quote_input(instance.name) + ")", r,
                    f, seconds(f), advice);
            }
    }
    // The environment, the cells and the portals do not move.
    const double zero[3] = {0, 0, 0};
    for (std::size_t e = 0; e < scene.environment.size(); ++e) {
        const EnvironmentObject& object = scene.environment[e];
        for (std::size_t k = 3 * std::size_t{object.first_triangle};
             k < 3 * (std::size_t{object.first_triangle} + object.triangle_count); ++k) {
            const std::uint32_t index = scene.occluder_indices[k];
            const DVec3 p = scene.occluder_world.empty() ? to_double(scene.occluder_vertices[index]) + world
                                                         : scene.occluder_world[index];
            const double c[3] = {p.x, p.y, p.z};
            if (const Reach r = beyond(c, c, zero); r.axis >= 0)
                motion_fail(source, "environment[" + std::to_string(e) + "]",
                            "the environment object (" + quote_input(object.name) + ")", r, 0, 0, advice);
        }
    }
    for (std::size_t i = 0; i < scene.cells.size(); ++i) {
        const Bounds& b = scene.cells[i].box;
        const DVec3 l = scene.cell_world.empty() ? to_double(b.min) + world : scene.cell_world[i][0];
        const DVec3 h = scene.cell_world.empty() ? to_double(b.max) + world : scene.cell_world[i][1];
        const double lo[3] = {l.x, l.y, l.z}, hi[3] = {h.x, h.y, h.z};
        if (const Reach r = beyond(lo, hi, zero); r.axis >= 0)
            motion_fail(source, "cells[" + std::to_string(i) + "]", "the cell", r, 0, 0, advice);
    }
    for (std::size_t i = 0; i < scene.portals.size(); ++i)
        for (std::size_t k = 0; k < 4; ++k) {
            const DVec3 p =
                scene.portal_world.empty() ? to_double(scene.portals[i].corners[k]) + world : scene.portal_world[i][k];
            const double c[3] = {p.x, p.y, p.z};
            if (const Reach r = beyond(c, c, zero); r.axis >= 0)
                motion_fail(source, "portals[" + std::to_string(i) + "].corners[" + std::to_string(k) + "]",
                            "the portal", r, 0, 0, advice);
        }
    // The camera: its eye and target at every frame (the path is not linear for an orbit).
    const CameraPath& c = scene.camera;
    const std::vector<WorldCamera> cameras = scene.world_camera_path(frames, 1.0f);
    for (int f = 0; f <= last; ++f) {
        const WorldCamera& cam = cameras[static_cast<std::size_t>(f)];
        const double eye[3] = {cam.eye.x, cam.eye.y, cam.eye.z};
        const double target[3] = {cam.target.x, cam.target.y, cam.target.z};
        if (const Reach r = beyond(eye, eye, zero); r.axis >= 0)
            motion_fail(source,
                        c.walk        ? (f == 0 ? "camera.walk.start" : "camera.walk.step")
                        : r.axis == 1 ? "camera.orbit.height"
                                      : "camera.orbit.distance",
                        "the camera's eye", r, f, seconds(f), advice);
        if (const Reach r = beyond(target, target, zero); r.axis >= 0)
            motion_fail(source, c.walk ? "camera.walk.direction" : "camera.orbit.target", "the camera's target", r, f,
                        seconds(f), advice);
    }
}

void place_scene_at_first_camera(Scene& scene, const std::string& source, int frames, double seconds_per_frame) {
    check_scene_motion(scene, source, frames, seconds_per_frame);
    const DVec3 origin = scene_frame_near(scene.world_camera_path(1, 1.0f).front().eye);
    const DVec3 now = scene.frame_origin;
    if (origin.x != now.x || origin.y != now.y || origin.z != now.z) rebase_scene_in_place(scene, origin);
    check_scene_motion(scene, source, frames, seconds_per_frame, kMaxSingleFrameReach, origin);
}

}  // namespace patchcull
