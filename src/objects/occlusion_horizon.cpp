// Occlusion horizon (patchcull/objects/occlusion_horizon.h): front-to-back sweep of occluders and
// objects, per-column covered intervals of window y, after Downs, Möller & Séquin, "Occlusion
// Horizons for Driving through Urban Scenery", and G. Zachmann's lecture "Advanced Visibility
// Computations". The conservativeness argument is in the header; comments here say which step
// of it a piece of code is.
#include "patchcull/objects/occlusion_horizon.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "patchcull/core/error.h"

namespace patchcull {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kInfF = std::numeric_limits<float>::infinity();
// Relative margin on the clip-space sign tests (w > 0, 0 <= z <= w), as hiz.h step 3: far above
// the double rounding of the corners (~1e-16 of the terms), so a corner on the eye plane or on a
// depth clip plane never passes by rounding.
constexpr double kSignMargin = 1.0 / (1 << 20);
constexpr int kMaxViewport = 16384;

enum class BoxKind { usable, empty, invalid };

BoxKind classify(const Bounds& b) {
    const float v[6] = {b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z};
    for (float f : v)
        if (std::isnan(f)) return BoxKind::invalid;
    if (b.min.x > b.max.x || b.min.y > b.max.y || b.min.z > b.max.z) return BoxKind::empty;
    for (float f : v)
        if (!std::isfinite(f)) return BoxKind::invalid;
    return BoxKind::usable;
}

// The 8 corners of a box in clip space (double), with the sums of absolute terms of rows z and w.
struct ClipCorners {
    double x[8], y[8], z[8], w[8], scale_z[8], scale_w[8];
};

void transform_corners(const double m[4][4], const Bounds& b, ClipCorners& out) {
    for (int k = 0; k < 8; ++k) {
        const double p[3] = {(k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y, (k & 4) ? b.max.z : b.min.z};
        double c[4], s[4];
        for (int r = 0; r < 4; ++r) {
            c[r] = m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3];
            s[r] =
                std::fabs(m[r][0] * p[0]) + std::fabs(m[r][1] * p[1]) + std::fabs(m[r][2] * p[2]) + std::fabs(m[r][3]);
        }
        out.x[k] = c[0], out.y[k] = c[1], out.z[k] = c[2], out.w[k] = c[3];
        out.scale_z[k] = s[2], out.scale_w[k] = s[3];
    }
}

// Every corner strictly in front of the eye plane (then the box projects to the hull of its
// corners). Written so that NaN fails.
bool in_front_of_eye(const ClipCorners& c) {
    for (int k = 0; k < 8; ++k)
        if (!(c.w[k] > kSignMargin * c.scale_w[k])) return false;
    return true;
}

// Every corner inside the depth range 0 <= z <= w (zero_to_one), so no part is depth-clipped.
bool inside_depth_range(const ClipCorners& c) {
    for (int k = 0; k < 8; ++k) {
        const double margin = kSignMargin * (c.scale_z[k] + c.scale_w[k]);
        if (!(c.z[k] > margin) || !(c.w[k] - c.z[k] > margin)) return false;
    }
    return true;
}

// Round a double to a float no smaller (up) or no larger (down): the stored intervals only shrink.
float round_up(double v) {
    float f = static_cast<float>(v);
    if (static_cast<double>(f) < v) f = std::nextafter(f, kInfF);
    return f;
}
float round_down(double v) {
    float f = static_cast<float>(v);
    if (static_cast<double>(f) > v) f = std::nextafter(f, -kInfF);
    return f;
}

struct Point2 {
    double x, y;
};

double cross(Point2 o, Point2 a, Point2 b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

// Convex hull (Andrew's monotone chain), counter-clockwise, collinear points dropped. Returns
// the vertex count (hull[0 .. n)); < 3 means no interior.
int convex_hull(Point2 (&pts)[8], Point2 (&hull)[16]) {
    std::sort(pts, pts + 8, [](Point2 a, Point2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    int n = 0;
    for (int i = 0; i < 8; ++i) {  // lower chain
        while (n >= 2 && cross(hull[n - 2], hull[n - 1], pts[i]) <= 0) --n;
        hull[n++] = pts[i];
    }
    for (int i = 6, lower = n + 1; i >= 0; --i) {  // upper chain
        while (n >= lower && cross(hull[n - 2], hull[n - 1], pts[i]) <= 0) --n;
        hull[n++] = pts[i];
    }
    return n - 1;  // the last point repeats the first
}

// One edge's line through a, moved inward by the pixel margin (offset, in y), as y of x;
// evaluated relative to a so that steep edges do not cancel.
struct EdgeBound {
    double ax, ay, slope, offset;
    double at(double x) const { return ay + slope * (x - ax) + offset; }
};

}  // namespace

void OcclusionHorizon::cull(const Mat4& world_to_clip, ClipDepth depth, int width, int height, const Bounds* occluders,
                            std::size_t occluder_count, const Bounds* objects, std::size_t object_count,
                            std::uint8_t* occluded, HorizonStats& stats) {
    if (width < 1 || width > kMaxViewport || height < 1 || height > kMaxViewport)
        throw Error("occlusion horizon: viewport " + std::to_string(width) + "x" + std::to_string(height) +
                    " outside 1..16384");
    if ((occluder_count > 0 && !occluders) || (object_count > 0 && (!objects || !occluded)))
        throw Error("occlusion horizon: null box or result array with a non-zero count");
    if (occluder_count > 0xffffffffu || object_count > 0xffffffffu)
        throw Error("occlusion horizon: more than 2^32 - 1 boxes");

    // The camera in double, depth row in zero_to_one form (z' = (z + w) / 2, or w - z for the
    // reversed conventions: clip_space.h), so that only forward depth is compared below.
    check_clip_depth(world_to_clip, depth, "occlusion horizon");
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) clip_[r][c] = world_to_clip.at(r, c);
    if (depth == ClipDepth::minus_one_to_one)
        for (int c = 0; c < 4; ++c) clip_[2][c] = 0.5 * (clip_[2][c] + clip_[3][c]);
    if (is_reversed(depth))
        for (int c = 0; c < 4; ++c) clip_[2][c] = clip_[3][c] - clip_[2][c];
    width_ = width;
    height_ = height;
    low_.assign(static_cast<std::size_t>(width), kInfF);
    high_.assign(static_cast<std::size_t>(width), -kInfF);

    // Occluders usable as such (file comment, step 1), keyed by their farthest w.
    ClipCorners corners;
    occluder_order_.clear();
    for (std::size_t i = 0; i < occluder_count; ++i) {
        bool usable = classify(occluders[i]) == BoxKind::usable;
        if (usable) {
            transform_corners(clip_, occluders[i], corners);
            usable = in_front_of_eye(corners) && inside_depth_range(corners);
        }
        if (!usable) {
            ++stats.occluders_skipped;
            continue;
        }
        occluder_order_.push_back({*std::max_element(corners.w, corners.w + 8), static_cast<std::uint32_t>(i)});
    }

    // Objects: empty ones draw nothing (occluded), invalid ones or ones crossing the eye plane
    // are visible (the sweep would insert no occluder before them anyway, since every occluder
    // lies beyond the near plane; the test keeps their projection out of covered()); the rest are
    // keyed by their nearest w.
    object_order_.clear();
    for (std::size_t i = 0; i < object_count; ++i) {
        ++stats.objects_tested;
        occluded[i] = 0;
        const BoxKind kind = classify(objects[i]);
        if (kind == BoxKind::empty) {
            occluded[i] = 1;
            ++stats.objects_occluded;
            continue;
        }
        if (kind == BoxKind::invalid) continue;
        transform_corners(clip_, objects[i], corners);
        if (!in_front_of_eye(corners)) continue;
        object_order_.push_back({*std::min_element(corners.w, corners.w + 8), static_cast<std::uint32_t>(i)});
    }

    // Front-to-back sweep (step 4): before an object is tested, every occluder strictly nearer
    // than all of it is in the horizon, and no other.
    const auto by_key = [](const Keyed& a, const Keyed& b) {
        return a.key < b.key || (a.key == b.key && a.index < b.index);
    };
    std::sort(occluder_order_.begin(), occluder_order_.end(), by_key);
    std::sort(object_order_.begin(), object_order_.end(), by_key);
    std::size_t next = 0;
    for (const Keyed& object : object_order_) {
        while (next < occluder_order_.size() && occluder_order_[next].key * (1 + kHorizonDepthMargin) < object.key) {
            insert(occluders[occluder_order_[next].index]);
            ++stats.occluders_inserted;
            ++next;
        }
        if (next > 0 && covered(objects[object.index])) {
            occluded[object.index] = 1;
            ++stats.objects_occluded;
        }
    }
}

// Step 2 and 3: the eroded hull's covered interval of every strip inside it, merged per column.
void OcclusionHorizon::insert(const Bounds& occluder) {
    ClipCorners c;
    transform_corners(clip_, occluder, c);
    const double half_w = 0.5 * width_, half_h = 0.5 * height_;
    Point2 pts[8];
    for (int k = 0; k < 8; ++k) pts[k] = {(c.x[k] / c.w[k] + 1) * half_w, (c.y[k] / c.w[k] + 1) * half_h};
    Point2 hull[16];
    const int n = convex_hull(pts, hull);
    if (n < 3) return;

    // Counter-clockwise edge a -> b, e = b - a: inside the eroded hull means
    // e.x (y - a.y) - e.y (x - a.x) >= r |e|. Edges going right (e.x > 0) bound y from below,
    // edges going left from above; vertical edges bound x only, at the hull's x extremes, which
    // the strip range below already keeps r away from.
    EdgeBound lower[16], upper[16];
    int lower_n = 0, upper_n = 0;
    double xmin = kInf, xmax = -kInf;
    for (int i = 0; i < n; ++i) {
        const Point2 a = hull[i], b = hull[i + 1 == n ? 0 : i + 1];
        xmin = std::min(xmin, a.x);
        xmax = std::max(xmax, a.x);
        const double ex = b.x - a.x, ey = b.y - a.y;
        if (ex == 0) continue;
        const double slope = ey / ex;
        const EdgeBound bound{a.x, a.y, slope, kHorizonPixelMargin * std::hypot(ex, ey) / ex};
        (ex > 0 ? lower[lower_n++] : upper[upper_n++]) = bound;
    }
    const double first = std::max(0.0, std::ceil(xmin + kHorizonPixelMargin));
    const double end = std::min(static_cast<double>(width_), std::floor(xmax - kHorizonPixelMargin));
    if (!(first < end)) return;  // also keeps the casts below in [0, width]
    for (int col = static_cast<int>(first); col < static_cast<int>(end); ++col) {
        const double x0 = col, x1 = col + 1.0;
        // lo is convex and hi concave along x: their values at the strip's edges bound them inside.
        double lo = 0, hi = height_;  // clamped to the viewport: nothing is drawn outside it
        for (int i = 0; i < lower_n; ++i) lo = std::max(lo, std::max(lower[i].at(x0), lower[i].at(x1)));
        for (int i = 0; i < upper_n; ++i) hi = std::min(hi, std::min(upper[i].at(x0), upper[i].at(x1)));
        if (!(lo <= hi)) continue;
        const float a = round_up(lo), b = round_down(hi);
        if (a > b) continue;
        float& low = low_[col];
        float& high = high_[col];
        // The first and last branches act alike for different reasons; the overlap test goes between.
        if (low > high) {  // NOLINT(bugprone-branch-clone): nothing covered yet
            low = a, high = b;
        } else if (a <= high && b >= low) {  // overlap or touch: every point of the union is covered
            low = std::min(low, a), high = std::max(high, b);
        } else if (b > high) {  // disjoint: keep the higher one (the horizon)
            low = a, high = b;
        }
    }
}

// Step 5: the object's grown window rectangle inside every overlapped column's interval.
bool OcclusionHorizon::covered(const Bounds& object) const {
    ClipCorners c;
    transform_corners(clip_, object, c);
    const double half_w = 0.5 * width_, half_h = 0.5 * height_;
    double x0 = kInf, x1 = -kInf, y0 = kInf, y1 = -kInf;
    for (int k = 0; k < 8; ++k) {
        const double x = (c.x[k] / c.w[k] + 1) * half_w, y = (c.y[k] / c.w[k] + 1) * half_h;
        x0 = std::min(x0, x), x1 = std::max(x1, x);
        y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
    if (!(x0 <= x1 && y0 <= y1)) return false;  // NaN
    x0 -= kHorizonPixelMargin, x1 += kHorizonPixelMargin;
    y0 = std::max(y0 - kHorizonPixelMargin, 0.0);
    y1 = std::min(y1 + kHorizonPixelMargin, static_cast<double>(height_));
    // Columns whose strip [c, c+1) meets [x0, x1], clipped to the viewport; none: outside.
    const double first = std::max(std::floor(x0), 0.0), last = std::min(std::floor(x1), width_ - 1.0);
    if (first > last || y0 > y1) return false;
    for (int col = static_cast<int>(first); col <= static_cast<int>(last); ++col)
        if (!(low_[col] <= y0 && y1 <= high_[col])) return false;
    return true;
}

}  // namespace patchcull
