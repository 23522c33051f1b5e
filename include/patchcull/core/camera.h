// patchcull/core/camera.h: perspective cameras and seeded random view generators.
//
// View modes (Niessner & Loop §6.2, Loop, Niessner & Eisenacher §7):
// - ViewMode::contain: every view contains the whole object: the camera looks at a point near
//   the object's centre from a random direction, far enough that the object's bounding sphere
//   lies inside the view volume, near and far planes included.
// - ViewMode::free: the camera is anywhere around or inside the object's (enlarged) bounding box
//   and looks in a random direction, with a random near distance down to 0.2% of the object's
//   size: parts leave the view and the near and far planes cut patches.
// Generators are deterministic for a seed on every platform (their own uniform conversion).
#pragma once

#include <cstdint>
#include <vector>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"

namespace patchcull {

struct Camera {
    Vec3 eye{0, 0, 5};
    Vec3 target{0, 0, 0};
    Vec3 up{0, 1, 0};
    float fovy_radians = 1.0471976f;  ///< 60 degrees
    float aspect = 1.0f;
    float z_near = 0.1f;
    float z_far = 100.0f;                      ///< ignored by ClipDepth::reversed_infinite
    ClipDepth depth = ClipDepth::zero_to_one;  ///< the convention projection() is written in

    Mat4 view() const { return look_at(eye, target, up); }
    Mat4 projection() const { return perspective(fovy_radians, aspect, z_near, z_far, depth); }
    /// projection() * view(): object (world) space to clip space.
    Mat4 view_projection() const { return projection() * view(); }
};

/// A camera placed in world coordinates (double), as an engine keeps it: objects and cameras at
/// 1e4 - 1e7 units. The kernels never see it: local() moves it into an object's local frame
/// (ControlMesh::origin, mesh.h), subtracting in double, so the float Camera, its view matrix
/// and object_to_clip hold only object-sized numbers and cull exactly as the same scene would at
/// the origin. (Composing view * translate(origin) in float instead, or float patches at world
/// coordinates, costs |translation| * 6e-8 units of precision: at 1e5 BigGuy's frustum tests
/// culled visible patches and ptp's rounding margin swallowed every cull.)
struct WorldCamera {
    DVec3 eye{0, 0, 5};
    DVec3 target{0, 0, 0};
    Vec3 up{0, 1, 0};
    float fovy_radians = 1.0471976f;
    float aspect = 1.0f;
    float z_near = 0.1f;
    float z_far = 100.0f;

    /// The same camera in the frame whose 0 is the world point origin: eye - origin and
    /// target - origin in double, each rounded once to float; other fields copied. A target
    /// nearer the eye than the eye is to origin first moves out along the view ray to that
    /// distance (the direction is what counts, and it survives the rounding). Its
    /// view_projection() is the object_to_clip of patches stored relative to origin.
    Camera local(DVec3 origin) const;
};

/// The world camera of a local one: eye and target plus origin, in double (inverse of local up
/// to the rounding of local's results).
WorldCamera to_world(const Camera& local_camera, DVec3 origin);

enum class ViewMode { contain, free };
const char* view_mode_name(ViewMode mode);
bool parse_view_mode(const char* text, ViewMode& mode);

class ViewGenerator {
public:
    ViewGenerator(const Bounds& object, ViewMode mode, std::uint64_t seed, float aspect = 1.0f);
    Camera next();

private:
    float uniform();  // [0, 1)
    Vec3 unit_vector();

    Bounds object_;
    ViewMode mode_;
    std::uint64_t state_;
    float aspect_;
};

/// frames cameras on a circle around the object, turning degrees_per_frame each frame, for
/// temporal tests; the whole object stays in view.
std::vector<Camera> orbit_sequence(const Bounds& object, int frames, float degrees_per_frame, float aspect = 1.0f);

}  // namespace patchcull
