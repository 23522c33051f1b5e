// Perspective cameras and seeded random views (patchcull/core/camera.h).
// contain mode follows Niessner & Loop §6.2 / Loop, Niessner & Eisenacher §7:
// views that contain the whole object.
#include "patchcull/core/camera.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace patchcull {

const char* view_mode_name(ViewMode mode) { return mode == ViewMode::contain ? "contain" : "free"; }

bool parse_view_mode(const char* text, ViewMode& mode) {
    if (std::strcmp(text, "contain") == 0)
        mode = ViewMode::contain;
    else if (std::strcmp(text, "free") == 0)
        mode = ViewMode::free;
    else
        return false;
    return true;
}

Camera WorldCamera::local(DVec3 origin) const {
    Camera cam;
    const DVec3 e = eye - origin;
    DVec3 d = target - eye;
    // look_at uses only the direction to the target; a target much nearer the eye than the eye
    // is to the origin would lose that direction in the rounding of both points to float, so it
    // moves out along the same ray, as far from the eye as the eye is from the origin.
    const double de = std::sqrt(e.x * e.x + e.y * e.y + e.z * e.z);
    const double dd = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    if (dd > 0 && dd < de) d = {d.x * (de / dd), d.y * (de / dd), d.z * (de / dd)};
    cam.eye = to_float(e);
    cam.target = to_float(e + d);
    cam.up = up;
    cam.fovy_radians = fovy_radians;
    cam.aspect = aspect;
    cam.z_near = z_near;
    cam.z_far = z_far;
    return cam;
}

WorldCamera to_world(const Camera& c, DVec3 origin) {
    WorldCamera w;
    w.eye = to_double(c.eye) + origin;
    w.target = to_double(c.target) + origin;
    w.up = c.up;
    w.fovy_radians = c.fovy_radians;
    w.aspect = c.aspect;
    w.z_near = c.z_near;
    w.z_far = c.z_far;
    return w;
}

ViewGenerator::ViewGenerator(const Bounds& object, ViewMode mode, std::uint64_t seed, float aspect)
    : object_(object), mode_(mode), state_(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull), aspect_(aspect) {}

float ViewGenerator::uniform() {
    // splitmix64, then the top 24 bits: identical on every platform and standard library.
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<float>(z >> 40) * (1.0f / 16777216.0f);
}

Vec3 ViewGenerator::unit_vector() {
    // Uniform on the sphere (Archimedes: z uniform, angle uniform).
    const float z = 2 * uniform() - 1;
    const float a = 6.2831853f * uniform();
    const float r = std::sqrt(std::max(0.0f, 1 - z * z));
    return {r * std::cos(a), r * std::sin(a), z};
}

Camera ViewGenerator::next() {
    Camera cam;
    cam.aspect = aspect_;
    const Vec3 c = object_.center();
    const float radius = std::max(object_.radius(), 1e-6f);
    if (mode_ == ViewMode::contain) {
        cam.fovy_radians = (30.0f + 40.0f * uniform()) * 3.14159265f / 180.0f;
        // Half-angle of the narrower side of the view: the bounding sphere must fit inside it.
        const float half_v = 0.5f * cam.fovy_radians;
        const float half_h = std::atan(std::tan(half_v) * std::min(aspect_, 1.0f));
        const float half = std::min(half_v, half_h);
        const float fit = radius / std::sin(half);  // distance at which the sphere touches the sides
        const float distance = fit * (1.05f + 1.5f * uniform());
        const Vec3 dir = unit_vector();
        cam.eye = c + dir * distance;
        // Aim slightly off centre while the sphere stays inside: the angular slack is the
        // difference between the half-angle and the sphere's angular radius.
        const float slack = half - std::asin(std::min(1.0f, radius / distance));
        const float offset = distance * std::tan(std::max(0.0f, slack) * 0.9f) * uniform();
        cam.target = c + normalize(cross(dir, unit_vector())) * offset;
        cam.up = unit_vector();
        cam.z_near = std::max(1e-4f * radius, (distance - radius) * 0.9f);
        cam.z_far = (distance + radius) * 1.1f;
    } else {
        // Anywhere around or inside the object; random direction;
        // near planes from 0.2% to 20% of the object's size so they cut patches; far planes that
        // sometimes cut the object too.
        // 40% of eyes inside the object's own box (the hard cases: patches all around, near
        // plane cutting through), the rest in the box enlarged 3x.
        const float spread = uniform() < 0.4f ? 0.5f : 1.5f;
        const Vec3 half = (object_.max - object_.min) * spread;
        cam.eye = c + Vec3{(2 * uniform() - 1) * half.x, (2 * uniform() - 1) * half.y, (2 * uniform() - 1) * half.z};
        const Vec3 toward_centre = normalize(c - cam.eye);
        const Vec3 dir = normalize(toward_centre * (uniform() < 0.6f ? 1.0f : 0.0f) + unit_vector() * 0.8f);
        // A target `radius` away, not one unit: eye + a unit vector rounds to a few directions
        // once the eye's coordinates reach ~1e6 (a large object in its own local frame).
        cam.target = cam.eye + (length(dir) > 0 ? dir : Vec3{0, 0, -1}) * radius;
        cam.up = unit_vector();
        cam.fovy_radians = (20.0f + 70.0f * uniform()) * 3.14159265f / 180.0f;
        cam.z_near = radius * (0.002f + 0.2f * uniform() * uniform());
        cam.z_far = radius * (0.5f + 5.0f * uniform());
    }
    return cam;
}

std::vector<Camera> orbit_sequence(const Bounds& object, int frames, float degrees_per_frame, float aspect) {
    std::vector<Camera> cameras;
    const Vec3 c = object.center();
    const float radius = std::max(object.radius(), 1e-6f);
    Camera base;
    base.aspect = aspect;
    const float half = 0.5f * base.fovy_radians * std::min(1.0f, aspect);
    const float distance = radius / std::sin(half) * 1.2f;
    for (int f = 0; f < frames; ++f) {
        Camera cam = base;
        const float a = f * degrees_per_frame * 3.14159265f / 180.0f;
        cam.eye = c + Vec3{distance * std::sin(a), 0.3f * distance, distance * std::cos(a)};
        cam.target = c;
        cam.z_near = std::max(1e-4f * radius, (length(cam.eye - c) - radius) * 0.9f);
        cam.z_far = (length(cam.eye - c) + radius) * 1.1f;
        cameras.push_back(cam);
    }
    return cameras;
}

}  // namespace patchcull
