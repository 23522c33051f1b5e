// The viewer's orbit and fly camera (viewer_camera.h).
#include "viewer_camera.h"

#include <algorithm>
#include <cmath>

namespace patchcull::cli {
namespace {

constexpr float kDegree = 0.017453292f;
constexpr float kMaxPitch = 89 * kDegree;

Vec3 direction(float yaw, float pitch) {
    return {std::cos(pitch) * std::sin(yaw), std::sin(pitch), -std::cos(pitch) * std::cos(yaw)};
}

void angles_of(Vec3 d, float& yaw, float& pitch) {
    const float len = length(d);
    if (!(len > 0)) return;
    d = d * (1 / len);
    pitch = std::asin(std::clamp(d.y, -1.0f, 1.0f));
    yaw = std::atan2(d.x, -d.z);
    pitch = std::clamp(pitch, -kMaxPitch, kMaxPitch);
}

}  // namespace

ViewerCamera::ViewerCamera(const Camera& start, Vec3 centre)
    : start_(start), centre_(centre), start_distance_(std::max(length(start.eye - centre), 1e-3f)) {
    reset();
}

void ViewerCamera::reset() { set_eye_and_target(start_.eye, start_.target); }

void ViewerCamera::set_eye_and_target(Vec3 eye, Vec3 target) {
    eye_ = eye;
    angles_of(target - eye, yaw_, pitch_);
}

Vec3 ViewerCamera::forward() const { return direction(yaw_, pitch_); }

void ViewerCamera::look_at_centre() { angles_of(centre_ - eye_, yaw_, pitch_); }

void ViewerCamera::orbit(float dx, float dy) {
    const Vec3 offset = eye_ - centre_;
    const float r = std::max(length(offset), 1e-3f);
    // The eye's direction from the centre, as yaw/pitch of a view direction (the opposite one).
    float yaw = 0, pitch = 0;
    angles_of(offset * -1.0f, yaw, pitch);
    yaw += dx * 0.25f * kDegree;  // drag right: the scene turns right, as if grabbed (the eye goes left)
    pitch = std::clamp(pitch - dy * 0.25f * kDegree, -kMaxPitch, kMaxPitch);
    eye_ = centre_ - direction(yaw, pitch) * r;
    look_at_centre();
}

void ViewerCamera::zoom(float steps) {
    const Vec3 offset = eye_ - centre_;
    const float r = std::max(length(offset), 1e-3f);
    const float target = std::clamp(r * std::pow(0.9f, steps), start_distance_ / 50, start_distance_ * 20);
    eye_ = centre_ + offset * (target / r);
    look_at_centre();
}

void ViewerCamera::look(float dx, float dy) {
    yaw_ += dx * 0.15f * kDegree;
    pitch_ = std::clamp(pitch_ - dy * 0.15f * kDegree, -kMaxPitch, kMaxPitch);
}

void ViewerCamera::move(float right, float up, float fwd, float seconds) {
    const float speed = 0.5f * start_distance_;  // the start distance in two seconds
    const Vec3 f = forward();
    Vec3 r = cross(f, Vec3{0, 1, 0});
    const float rl = length(r);
    r = rl > 0 ? r * (1 / rl) : Vec3{1, 0, 0};
    eye_ = eye_ + (r * right + Vec3{0, 1, 0} * up + f * fwd) * (speed * seconds);
}

Camera ViewerCamera::camera() const {
    Camera c = start_;
    c.eye = eye_;
    c.target = eye_ + forward() * start_distance_;
    c.up = {0, 1, 0};
    c.z_far = start_.z_far + std::max(0.0f, length(eye_ - centre_) - start_distance_);
    return c;
}

Camera second_status_camera(const Camera& camera) {
    // As `demo` draws cull.png (tools/cmd_demo.cpp): turned 90 degrees about the target, 1.4 times
    // as far, 1.8 units up.
    Camera overview = camera;
    const Vec3 d = overview.eye - overview.target;
    overview.eye = overview.target + Vec3{-d.z, 0, d.x} * 1.4f + Vec3{0, 1.8f, 0};
    overview.fovy_radians = 1.0471976f;
    overview.z_far *= 2;
    return overview;
}

}  // namespace patchcull::cli
