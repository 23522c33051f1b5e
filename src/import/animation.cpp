// Procedural control-mesh animation (patchcull/import/animation.h).
//
// Model. Let B be the rest bounds (compute_bounds), a the vertical axis (the axis of B's longest
// extent; ties prefer z, then y, then x), h1 = (a+1)%3 and h2 = (a+2)%3 the horizontal axes,
// H = B's extent along a, s = (p_a - B.min_a) / H in [0, 1] a vertex's relative height, and
// phase = sin(2*pi*t / period) (zero at t = 0). Each rest vertex p goes through, in this order:
//   1. breathing: its horizontal offset from the vertical axis through B.center() is scaled by
//      1 + breathe_amplitude * phase;
//   2. twist: that offset is rotated about the same axis by twist_radians * phase * (s - 1/2), so
//      top and bottom turn against each other by twist_radians * phase;
//   3. bend: the point is rotated in the (h1, a) plane, i.e. about a horizontal axis parallel to
//      h2 through the bottom centre (B.center() with the a-coordinate B.min_a), by
//      bend_radians * phase * s: the base stays, the top leans over.
// Every step is a polynomial/trigonometric function of the rest coordinates, so the map is smooth
// (C-infinity) in space and time. The displacement of each step is computed directly (rotation
// minus identity), so at phase = 0 every displacement is exactly zero and out == rest bit for bit.
//
// Bound. With D = |B.max - B.min| the bounds' diagonal (2 * B.radius()) and A, T, Bd the absolute
// breathe, twist and bend parameters, no vertex moves farther than
//     D * (A/2 + (1 + A) * (T/4 + Bd)).
// (Breathing moves a point by at most A * D/2; twisting a point at most (1+A)*D/2 from the axis by
// at most T/2 radians moves it by at most (T/2)(1+A)D/2; the bend turns a point at most (1+A)*D from
// the pivot by at most Bd radians.) With the default parameters that is 0.514 D; in practice the
// top of the model moves about bend_radians * H.
//
// A non-positive or non-finite period, or a non-finite time, leaves the mesh at rest; a point set
// with zero extent along every axis is copied unchanged. out may be the same vector as rest.
// Nothing is allocated beyond out.resize(rest.size()).
#include "patchcull/import/animation.h"

#include <cmath>

namespace patchcull {
namespace {

float& component(Vec3& v, int axis) { return axis == 0 ? v.x : (axis == 1 ? v.y : v.z); }
float component(const Vec3& v, int axis) { return axis == 0 ? v.x : (axis == 1 ? v.y : v.z); }

/// Rotation by angle minus the identity applied to (x, y): the displacement of (x, y).
/// cos - 1 is written as -2 sin^2(angle/2), so small angles keep their precision.
void rotation_delta(float angle, float x, float y, float& dx, float& dy) {
    const float s = std::sin(angle);
    const float h = std::sin(0.5f * angle);
    const float c1 = -2.0f * h * h;  // cos(angle) - 1
    dx = c1 * x - s * y;
    dy = s * x + c1 * y;
}

}  // namespace

void animate(const std::vector<Vec3>& rest, float time_seconds, const AnimationParams& params, std::vector<Vec3>& out) {
    out.resize(rest.size());
    if (rest.empty()) return;

    double phase = 0.0;
    const double period = params.period_seconds;
    if (period > 0.0 && std::isfinite(period) && std::isfinite(time_seconds)) {
        // Reduce t modulo the period in double first so long-running clocks keep their precision.
        const double t = std::fmod(static_cast<double>(time_seconds), period);
        phase = std::sin(2.0 * 3.14159265358979323846 * t / period);
    }

    const Bounds bounds = compute_bounds(rest);
    const Vec3 extent = bounds.max - bounds.min;
    int a = 2;
    if (extent.y > extent.z) a = 1;
    if (extent.x > component(extent, a)) a = 0;
    const int h1 = (a + 1) % 3;
    const int h2 = (a + 2) % 3;
    const float height = component(extent, a);
    if (phase == 0.0 || !(height > 0.0f) || !std::isfinite(height)) {
        if (&out != &rest) out.assign(rest.begin(), rest.end());
        return;
    }

    const Vec3 center = bounds.center();
    const float c1 = component(center, h1);
    const float c2 = component(center, h2);
    const float base = component(bounds.min, a);
    const float inv_height = 1.0f / height;
    const float ph = static_cast<float>(phase);
    const float breathe = params.breathe_amplitude * ph;
    const float twist = params.twist_radians * ph;
    const float bend = params.bend_radians * ph;

    for (std::size_t k = 0; k < rest.size(); ++k) {
        const Vec3 p = rest[k];
        const float x1 = component(p, h1) - c1;  // horizontal offset from the vertical axis
        const float x2 = component(p, h2) - c2;
        const float y = component(p, a) - base;  // height above the base
        const float s = y * inv_height;

        // 1. breathing
        float d1 = breathe * x1;
        float d2 = breathe * x2;
        // 2. twist about the vertical axis
        float t1, t2;
        rotation_delta(twist * (s - 0.5f), x1 + d1, x2 + d2, t1, t2);
        d1 += t1;
        d2 += t2;
        // 3. bend about a horizontal axis (parallel to h2) through the bottom centre
        float b1, by;
        rotation_delta(bend * s, x1 + d1, y, b1, by);
        d1 += b1;

        Vec3 q = p;
        component(q, h1) += d1;
        component(q, h2) += d2;
        component(q, a) += by;
        out[k] = q;
    }
}

}  // namespace patchcull
