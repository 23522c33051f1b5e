// Bounds of displaced bicubic patches and their frustum / Hi-Z occlusion tests
// (patchcull/core/displaced_bounds.h, where the conventions and every formula are written out).
//
// Sources:
// - Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation" §4.2:
//   the camera-aligned frustum (CAF), the per-axis cone extensions delta+- and P_max / P_min, the
//   Full / ACoN / CoN variants (§6.2 Table 1, Fig. 7);
// - Munkberg, Hasselgren, Toth & Akenine-Moeller, "Efficient bounding of displaced Bezier
//   patches", HPG 2010: the object-oriented bounding box (OOBB) with cone-of-normals extensions,
//   the comparison of Niessner & Loop, Table 1 (our reading of it is in the header);
// - the cones themselves are cones.h's (Sederberg & Meyers 1988; Shirman & Abi-Ezzi 1993).
//
// Derivation of delta+- without acos (Niessner & Loop write max(cos(acos(a_x) + alpha),
// cos(acos(a_x) - alpha))): for a unit direction r at angle theta in [0, pi] from the cone axis, the
// unit vectors of the cone make angles with r in [max(0, theta - alpha), min(pi, theta + alpha)];
// cos is decreasing there, so max r.n = 1 when theta <= alpha, else cos(theta - alpha) =
// cos(theta) cos(alpha) + sin(theta) sin(alpha), which is >= cos(theta + alpha) since sin(theta) and
// sin(alpha) are >= 0: the seed's max always picks the theta - alpha term. sin(theta) is taken as
// |r x a| rather than sqrt(1 - c^2): near theta = 0 or pi the latter turns a 1e-7 error in c into
// 4e-4 in s; the cross product stays accurate in absolute terms.
// Interval product: D in [d_min, d_max] (d_min <= 0 <= d_max), r.n in [-delta-, delta+] with
// -delta- <= delta+; of the four corner products, d_max * (-delta-) <= d_max * delta+ and
// d_min * delta+ <= -d_min * delta- (because delta- >= -delta+), so the max of r.(D n) is
// max(d_max delta+, -d_min delta-) and the min is -max(d_max delta-, -d_min delta+): the seed's
// P_max / P_min.
#include "patchcull/core/displaced_bounds.h"

#include <cmath>
#include <cstring>
#include <limits>

#include "core/cones_internal.h"

// std::fma is a libm call on the x86-64 baseline: as in frustum.cpp and backpatch_cones.cpp, an
// FMA clone of each public entry point is compiled and picked once at load time (results are
// identical: fma is exactly rounded either way). Everything below them, the cone constructions of
// cones_internal.h included, is always_inline, so it is compiled into each clone.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(__SANITIZE_ADDRESS__)
#define PATCHCULL_DISPLACED_CLONES __attribute__((target_clones("fma", "default")))
#else
#define PATCHCULL_DISPLACED_CLONES
#endif
#define PATCHCULL_DISPLACED_INLINE PATCHCULL_CONES_INLINE

namespace patchcull {
namespace {

inline float min_f(float a, float b) { return a < b ? a : b; }
inline float max_f(float a, float b) { return a > b ? a : b; }
inline float dot3(Vec3 a, Vec3 b) { return std::fma(a.z, b.z, std::fma(a.y, b.y, a.x * b.x)); }
inline Vec3 cross3(Vec3 a, Vec3 b) {
    return {std::fma(a.y, b.z, -(a.z * b.y)), std::fma(a.z, b.x, -(a.x * b.z)), std::fma(a.x, b.y, -(a.y * b.x))};
}
inline bool all_finite(const float* v, int n) {
    // x * 0 is 0 for finite x and NaN for inf/NaN; a sum of zeros never overflows.
    float probe = 0.0f;
    for (int i = 0; i < n; ++i) probe += v[i] * 0.0f;
    return probe == 0.0f;
}

/// Range of r.d for the displacement vector d = D n, along a direction of length `length` whose
/// unit vector is r (header: "Cones and per-axis extensions"): r.d in [-minus, plus].
struct AxisExtension {
    float plus = 0, minus = 0;
};

PATCHCULL_DISPLACED_INLINE AxisExtension extension_along(Vec3 r, float length, const NormalCone& cone, float d_min,
                                                         float d_max, float radius) {
    const float scale = length * kDisplacedExtScale;
    if (!cone.valid) return {radius * scale, radius * scale};
    const float c = dot3(r, cone.axis);
    const Vec3 x = cross3(r, cone.axis);
    const float s = std::sqrt(dot3(x, x));
    const float ca = cone.cos_angle, sa = cone.sin_angle;
    const float sin_term = s * sa;
    const float delta_plus = c >= ca ? 1.0f : min_f(1.0f, std::fma(c, ca, sin_term) + kDisplacedDeltaSlack);
    const float delta_minus = -c >= ca ? 1.0f : min_f(1.0f, std::fma(-c, ca, sin_term) + kDisplacedDeltaSlack);
    AxisExtension e;
    e.plus = max_f(d_max * delta_plus, -d_min * delta_minus) * scale;
    e.minus = max_f(d_max * delta_minus, -d_min * delta_plus) * scale;
    return e;
}

/// View-space point (x, y, t = -z) of an object-space point, and the magnitude of t's terms.
struct ViewPoint {
    float x, y, t, t_terms;
};

PATCHCULL_DISPLACED_INLINE ViewPoint to_view(const Mat4& v, const float abs_row_z[4], Vec3 p) {
    ViewPoint q;
    q.x = std::fma(v.at(0, 2), p.z, std::fma(v.at(0, 1), p.y, v.at(0, 0) * p.x)) + v.at(0, 3);
    q.y = std::fma(v.at(1, 2), p.z, std::fma(v.at(1, 1), p.y, v.at(1, 0) * p.x)) + v.at(1, 3);
    q.t = -(std::fma(v.at(2, 2), p.z, std::fma(v.at(2, 1), p.y, v.at(2, 0) * p.x)) + v.at(2, 3));
    q.t_terms =
        std::fma(abs_row_z[2], std::fabs(p.z), std::fma(abs_row_z[1], std::fabs(p.y), abs_row_z[0] * std::fabs(p.x))) +
        abs_row_z[3];
    return q;
}

/// Step 5 of the header: NDC rectangle and depths from x/t, y/t ranges and the view depth range.
PATCHCULL_DISPLACED_INLINE DisplacedBound to_screen(const DisplacedCullView& view, float x_min, float x_max,
                                                    float y_min, float y_max, float t_front, float t_back) {
    const Mat4& p = view.projection;
    const float ax = std::fma(p.at(0, 0), x_min, -p.at(0, 2)), bx = std::fma(p.at(0, 0), x_max, -p.at(0, 2));
    const float ay = std::fma(p.at(1, 1), y_min, -p.at(1, 2)), by = std::fma(p.at(1, 1), y_max, -p.at(1, 2));
    // Depth as hiz.h computes it: clip z (one fma: z_clip = P22 z + P23 with z = -t) over w = t,
    // correctly rounded, so it is exact relative to the computed clip coordinates.
    const float df = std::fma(-p.at(2, 2), t_front, p.at(2, 3)) / t_front;
    const float db = std::fma(-p.at(2, 2), t_back, p.at(2, 3)) / t_back;
    DisplacedBound b;
    b.ndc_xmin = min_f(ax, bx);
    b.ndc_xmax = max_f(ax, bx);
    b.ndc_ymin = min_f(ay, by);
    b.ndc_ymax = max_f(ay, by);
    b.depth_near = min_f(df, db);
    b.depth_far = max_f(df, db);
    b.key_near = view.key_near;
    b.key_far = view.key_far;
    const float out[6] = {b.ndc_xmin, b.ndc_xmax, b.ndc_ymin, b.ndc_ymax, b.depth_near, b.depth_far};
    b.status = all_finite(out, 6) ? kDisplacedBoundProjected : kDisplacedBoundInvalid;
    return b;
}

PATCHCULL_DISPLACED_INLINE DisplacedBound unprojectable(bool outside_plane) {
    DisplacedBound b;
    b.status = outside_plane ? kDisplacedBoundOutsidePlane : kDisplacedBoundUnprojectable;
    return b;
}

PATCHCULL_DISPLACED_INLINE DisplacedBound invalid_bound() { return DisplacedBound{}; }

// ---- caf ------------------------------------------------------------------------------------------

PATCHCULL_DISPLACED_INLINE DisplacedBound caf_bound(const Vec3 p[kPatchPoints], const NormalCone& cone, float d_min,
                                                    float d_max, float radius, const DisplacedCullView& view) {
    // Step 2: extensions along the view axes (rows of L).
    AxisExtension ext[3];
    for (int i = 0; i < 3; ++i)
        ext[i] = extension_along(view.axis_unit[i], view.axis_length[i], cone, d_min, d_max, radius);
    // View +z points towards the eye: a box reaches ext[2].plus nearer (smaller t) and ext[2].minus farther.
    const float t_near_ext = ext[2].plus, t_far_ext = ext[2].minus;

    // Steps 1 and 3.
    ViewPoint q[kPatchPoints];
    float t_min = 0, t_max = 0, terms = 0;
    for (int k = 0; k < kPatchPoints; ++k) {
        q[k] = to_view(view.object_to_view, view.abs_row_z, p[k]);
        t_min = k == 0 ? q[k].t : min_f(t_min, q[k].t);
        t_max = k == 0 ? q[k].t : max_f(t_max, q[k].t);
        terms = k == 0 ? q[k].t_terms : max_f(terms, q[k].t_terms);
    }
    const float t_front = t_min - t_near_ext;
    const float t_back = t_max + t_far_ext;
    const float margin = kDisplacedDepthSafety * (terms + t_near_ext);
    if (!(t_front > margin)) {
        // Not projectable: homogeneous plane test of the 16 boxes (view-space planes).
        bool outside = false;
        for (int plane = 0; plane < 6; ++plane) {
            const Vec4 r = view.view_planes.rows[plane];
            // Box extent term: the largest value of r.xyz . e over the displacement box [-minus, plus].
            // View z of a box point is -t, so along z the same rule applies to the view-z extensions.
            const float mx = max_f(r.x * ext[0].plus, -r.x * ext[0].minus);
            const float my = max_f(r.y * ext[1].plus, -r.y * ext[1].minus);
            const float mz = max_f(r.z * ext[2].plus, -r.z * ext[2].minus);
            const float box_margin = (mx + my) + mz;
            float best = 0;
            for (int k = 0; k < kPatchPoints; ++k) {
                const float value = std::fma(r.z, -q[k].t, std::fma(r.y, q[k].y, r.x * q[k].x)) + r.w;
                best = k == 0 ? value : max_f(best, value);
            }
            outside = outside || (best + box_margin < 0.0f);
        }
        const float all[3] = {t_front, t_back, margin};
        if (!all_finite(all, 3)) return invalid_bound();
        return unprojectable(outside);
    }
    // Step 4: extremes of x/t and y/t over each box (at its corners).
    float x_min = 0, x_max = 0, y_min = 0, y_max = 0;
    for (int k = 0; k < kPatchPoints; ++k) {
        const float t_lo = q[k].t - t_near_ext, t_hi = q[k].t + t_far_ext;  // t_lo >= t_front > 0
        const float x_lo = q[k].x - ext[0].minus, x_hi = q[k].x + ext[0].plus;
        const float y_lo = q[k].y - ext[1].minus, y_hi = q[k].y + ext[1].plus;
        const float bx_lo = x_lo / (x_lo >= 0.0f ? t_hi : t_lo), bx_hi = x_hi / (x_hi >= 0.0f ? t_lo : t_hi);
        const float by_lo = y_lo / (y_lo >= 0.0f ? t_hi : t_lo), by_hi = y_hi / (y_hi >= 0.0f ? t_lo : t_hi);
        x_min = k == 0 ? bx_lo : min_f(x_min, bx_lo);
        x_max = k == 0 ? bx_hi : max_f(x_max, bx_hi);
        y_min = k == 0 ? by_lo : min_f(y_min, by_lo);
        y_max = k == 0 ? by_hi : max_f(y_max, by_hi);
    }
    return to_screen(view, x_min, x_max, y_min, y_max, t_front, t_back);
}

// ---- oobb -------------------------------------------------------------------------------------------

/// Orthonormal frame (up to rounding) of the OOBB: e[0] = e_u, e[1] = e_v, e[2] = e_n.
PATCHCULL_DISPLACED_INLINE void oobb_frame(const Vec3 p[kPatchPoints], Vec3 e[3]) {
    // The same frame for every cone kind, so that the cones only change the extensions (a tighter
    // cone then gives a box inside the full one; with the cone axis as e_n the frames would differ).
    Vec3 n = normalize(cross3(p[3] - p[12], p[15] - p[0]));  // corner diagonals P30 - P03 and P33 - P00
    if (dot3(n, n) == 0.0f) n = {0, 0, 1};
    Vec3 u = (p[3] + p[15]) - (p[0] + p[12]);  // u direction: P30 + P33 - P00 - P03
    u = normalize(u - n * dot3(u, n));
    if (dot3(u, u) == 0.0f) u = normalize(cross3(n, std::fabs(n.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
    e[0] = u;
    e[1] = cross3(n, u);
    e[2] = n;
}

PATCHCULL_DISPLACED_INLINE DisplacedBound oobb_bound(const Vec3 p[kPatchPoints], const NormalCone& cone, float d_min,
                                                     float d_max, float radius, const DisplacedCullView& view) {
    Vec3 e[3];
    oobb_frame(p, e);
    const Vec3 origin = p[0];
    float lo[3], hi[3];
    for (int k = 0; k < kPatchPoints; ++k) {
        const Vec3 d = p[k] - origin;
        for (int i = 0; i < 3; ++i) {
            const float c = dot3(e[i], d);
            lo[i] = k == 0 ? c : min_f(lo[i], c);
            hi[i] = k == 0 ? c : max_f(hi[i], c);
        }
    }
    float size = 0;
    for (int i = 0; i < 3; ++i) {
        const AxisExtension x = extension_along(e[i], 1.0f, cone, d_min, d_max, radius);
        lo[i] -= x.minus;
        hi[i] += x.plus;
        size = max_f(size, max_f(std::fabs(lo[i]), std::fabs(hi[i])));
    }
    const float pad = kDisplacedFramePad * size;
    for (int i = 0; i < 3; ++i) {
        lo[i] -= pad;
        hi[i] += pad;
    }
    ViewPoint corner[8];
    float t_min = 0, t_max = 0, terms = 0;
    for (int c = 0; c < 8; ++c) {
        const float a = (c & 1) ? hi[0] : lo[0], b = (c & 2) ? hi[1] : lo[1], g = (c & 4) ? hi[2] : lo[2];
        const Vec3 x{origin.x + std::fma(e[2].x, g, std::fma(e[1].x, b, e[0].x * a)),
                     origin.y + std::fma(e[2].y, g, std::fma(e[1].y, b, e[0].y * a)),
                     origin.z + std::fma(e[2].z, g, std::fma(e[1].z, b, e[0].z * a))};
        corner[c] = to_view(view.object_to_view, view.abs_row_z, x);
        t_min = c == 0 ? corner[c].t : min_f(t_min, corner[c].t);
        t_max = c == 0 ? corner[c].t : max_f(t_max, corner[c].t);
        terms = c == 0 ? corner[c].t_terms : max_f(terms, corner[c].t_terms);
    }
    if (!(t_min > kDisplacedDepthSafety * terms)) {
        bool outside = false;
        for (int plane = 0; plane < 6; ++plane) {
            const Vec4 r = view.view_planes.rows[plane];
            float best = 0;
            for (int c = 0; c < 8; ++c) {
                const float value = std::fma(r.z, -corner[c].t, std::fma(r.y, corner[c].y, r.x * corner[c].x)) + r.w;
                best = c == 0 ? value : max_f(best, value);
            }
            outside = outside || best < 0.0f;
        }
        const float all[2] = {t_min, t_max};
        if (!all_finite(all, 2)) return invalid_bound();
        return unprojectable(outside);
    }
    float x_min = 0, x_max = 0, y_min = 0, y_max = 0;
    for (int c = 0; c < 8; ++c) {
        const float x = corner[c].x / corner[c].t, y = corner[c].y / corner[c].t;
        x_min = c == 0 ? x : min_f(x_min, x);
        x_max = c == 0 ? x : max_f(x_max, x);
        y_min = c == 0 ? y : min_f(y_min, y);
        y_max = c == 0 ? y : max_f(y_max, y);
    }
    return to_screen(view, x_min, x_max, y_min, y_max, t_min, t_max);
}

PATCHCULL_DISPLACED_INLINE BezierPatch gather(const PatchBatchView& v, std::size_t index) {
    BezierPatch patch;
    for (int k = 0; k < kPatchPoints; ++k)
        patch.cp[k] = {v.at(index, k, 0), v.at(index, k, 1), v.at(index, k, 2), v.at(index, k, 3)};
    return patch;
}

PATCHCULL_DISPLACED_INLINE NormalCone cone_of(const BezierPatch& patch, NormalConeKind kind) {
    // cones.h's entry points without the call: rational patches get no cone (full), as there.
    if (kind == NormalConeKind::full || !cones_detail::is_polynomial(patch)) return NormalCone{};
    return kind == NormalConeKind::acon ? cones_detail::tangent_cone_polynomial(patch)
                                        : cones_detail::normal_cone_polynomial(patch);
}

PATCHCULL_DISPLACED_INLINE DisplacedBound bound_with_cone(const BezierPatch& patch, DisplacementRange range,
                                                          const NormalCone& cone, DisplacedBoundKind kind,
                                                          const DisplacedCullView& view) {
    if (!view.valid) return invalid_bound();
    const float r[2] = {range.d_min, range.d_max};
    if (!all_finite(&patch.cp[0].x, 4 * kPatchPoints) || !all_finite(r, 2)) return invalid_bound();
    Vec3 p[kPatchPoints];
    bool positive = true;
    for (int k = 0; k < kPatchPoints; ++k) {
        const Vec4 c = patch.cp[k];
        positive = positive && c.w > 0.0f;
        p[k] = c.w == 1.0f ? Vec3{c.x, c.y, c.z} : Vec3{c.x / c.w, c.y / c.w, c.z / c.w};
    }
    if (!positive || !all_finite(&p[0].x, 3 * kPatchPoints)) return invalid_bound();
    // The bounds need 0 in the range (D = 0 everywhere is the undisplaced patch); widening is conservative.
    const float d_min = min_f(range.d_min, 0.0f), d_max = max_f(range.d_max, 0.0f);
    const float radius = max_f(d_max, -d_min);
    const NormalCone used = cone.valid && all_finite(&cone.axis.x, 3) ? cone : NormalCone{};
    return kind == DisplacedBoundKind::caf ? caf_bound(p, used, d_min, d_max, radius, view)
                                           : oobb_bound(p, used, d_min, d_max, radius, view);
}

PATCHCULL_DISPLACED_INLINE DisplacedBound bound_of(const BezierPatch& patch, DisplacementRange range,
                                                   DisplacedBoundKind kind, NormalConeKind cone,
                                                   const DisplacedCullView& view) {
    // Nothing to displace: skip the cone (the bound does not depend on it then).
    const bool displaced = range.d_min != 0.0f || range.d_max != 0.0f;
    return bound_with_cone(patch, range, displaced ? cone_of(patch, cone) : NormalCone{}, kind, view);
}

PATCHCULL_DISPLACED_INLINE bool outside_frustum(const DisplacedBound& b) {
    if (b.status == kDisplacedBoundOutsidePlane) return true;
    if (b.status != kDisplacedBoundProjected) return false;
    return b.ndc_xmax < -1.0f || b.ndc_xmin > 1.0f || b.ndc_ymax < -1.0f || b.ndc_ymin > 1.0f ||
           b.depth_near > b.key_far || b.depth_far < b.key_near;
}

PATCHCULL_DISPLACED_INLINE std::uint8_t hiz_decision(const DisplacedBound& b, const HiZPyramid& hiz) {
    if (outside_frustum(b)) return kHiZFrustumCulled;
    if (b.status != kDisplacedBoundProjected) return kHiZVisible;
    const float half_w = 0.5f * static_cast<float>(hiz.depth_width());
    const float half_h = 0.5f * static_cast<float>(hiz.depth_height());
    const float xlo = std::fma(b.ndc_xmin, half_w, half_w), xhi = std::fma(b.ndc_xmax, half_w, half_w);
    const float ylo = std::fma(b.ndc_ymin, half_h, half_h), yhi = std::fma(b.ndc_ymax, half_h, half_h);
    const PixelRect rect = hiz_rect_from_window_box(xlo, xhi, ylo, yhi, hiz.depth_width(), hiz.depth_height());
    return hiz_rect_max(hiz, rect) < b.depth_near ? kHiZOccluded : kHiZVisible;  // hiz.h step 9
}

}  // namespace

const char* displaced_bound_name(DisplacedBoundKind kind) { return kind == DisplacedBoundKind::oobb ? "oobb" : "caf"; }

const char* normal_cone_name(NormalConeKind kind) {
    switch (kind) {
        case NormalConeKind::full:
            return "full";
        case NormalConeKind::acon:
            return "acon";
        case NormalConeKind::con:
            return "con";
    }
    return "?";
}

bool parse_displaced_bound(const char* text, DisplacedBoundKind& kind) {
    if (std::strcmp(text, "oobb") == 0)
        kind = DisplacedBoundKind::oobb;
    else if (std::strcmp(text, "caf") == 0)
        kind = DisplacedBoundKind::caf;
    else
        return false;
    return true;
}

bool parse_normal_cone(const char* text, NormalConeKind& kind) {
    if (std::strcmp(text, "full") == 0)
        kind = NormalConeKind::full;
    else if (std::strcmp(text, "acon") == 0)
        kind = NormalConeKind::acon;
    else if (std::strcmp(text, "con") == 0)
        kind = NormalConeKind::con;
    else
        return false;
    return true;
}

DisplacedCullView make_displaced_cull_view(const Mat4& object_to_view, const Mat4& any_projection, ClipDepth depth) {
    DisplacedCullView v;
    v.view_planes = make_frustum_planes(any_projection, depth);  // refuses a contradicting matrix
    const Mat4 projection = to_depth_key(any_projection, depth);
    v.object_to_view = object_to_view;
    v.projection = projection;
    v.depth = depth;
    v.key_near = is_reversed(depth) ? -1.0f : 0.0f;
    v.key_far = !has_far_plane(depth) ? std::numeric_limits<float>::infinity() : is_reversed(depth) ? 0.0f : 1.0f;
    const Mat4& p = projection;
    const bool frustum_form = p.at(0, 1) == 0 && p.at(0, 3) == 0 && p.at(1, 0) == 0 && p.at(1, 3) == 0 &&
                              p.at(2, 0) == 0 && p.at(2, 1) == 0 && p.at(3, 0) == 0 && p.at(3, 1) == 0 &&
                              p.at(3, 2) == -1.0f && p.at(3, 3) == 0 && p.at(0, 0) != 0 && p.at(1, 1) != 0 &&
                              p.at(2, 3) != 0;
    const Mat4& m = object_to_view;
    const bool affine = m.at(3, 0) == 0 && m.at(3, 1) == 0 && m.at(3, 2) == 0 && m.at(3, 3) == 1.0f;
    bool rows_ok = true;
    for (int i = 0; i < 3; ++i) {
        const Vec3 r{m.at(i, 0), m.at(i, 1), m.at(i, 2)};
        const double len = std::sqrt(double(r.x) * r.x + double(r.y) * r.y + double(r.z) * r.z);
        v.axis_length[i] = static_cast<float>(len);
        v.axis_unit[i] = len > 0 ? Vec3{float(r.x / len), float(r.y / len), float(r.z / len)} : Vec3{};
        rows_ok = rows_ok && len > 0 && std::isfinite(v.axis_length[i]);
    }
    for (int c = 0; c < 4; ++c) v.abs_row_z[c] = std::fabs(m.at(2, c));
    v.valid = frustum_form && affine && rows_ok && all_finite(p.m, 16) && all_finite(m.m, 16);
    return v;
}

NormalCone displaced_normal_cone(const BezierPatch& patch, NormalConeKind cone) { return cone_of(patch, cone); }

PATCHCULL_DISPLACED_CLONES
DisplacedBound compute_displaced_bound_with_cone(const BezierPatch& patch, DisplacementRange range,
                                                 const NormalCone& cone, DisplacedBoundKind kind,
                                                 const DisplacedCullView& view) {
    return bound_with_cone(patch, range, cone, kind, view);
}

PATCHCULL_DISPLACED_CLONES
DisplacedBound compute_displaced_bound(const BezierPatch& patch, DisplacementRange range, DisplacedBoundKind kind,
                                       NormalConeKind cone, const DisplacedCullView& view) {
    return bound_of(patch, range, kind, cone, view);
}

bool displaced_bound_outside_frustum(const DisplacedBound& bound) { return outside_frustum(bound); }

PATCHCULL_DISPLACED_CLONES
std::uint8_t displaced_bound_hiz_decision(const DisplacedBound& bound, const HiZPyramid& hiz) {
    return hiz_decision(bound, hiz);
}

PATCHCULL_DISPLACED_CLONES
void compute_displaced_bounds(const PatchBatchView& patches, const DisplacementRange* ranges, DisplacedBoundKind kind,
                              NormalConeKind cone, const DisplacedCullView& view, DisplacedBound* out) {
    for (std::size_t i = 0; i < patches.count; ++i)
        out[i] = bound_of(gather(patches, i), ranges ? ranges[i] : DisplacementRange{}, kind, cone, view);
}

PATCHCULL_DISPLACED_CLONES
void cull_displaced_frustum(const PatchBatchView& patches, const DisplacementRange* ranges, DisplacedBoundKind kind,
                            NormalConeKind cone, const DisplacedCullView& view, std::uint8_t* culled) {
    for (std::size_t i = 0; i < patches.count; ++i) {
        const DisplacedBound b =
            bound_of(gather(patches, i), ranges ? ranges[i] : DisplacementRange{}, kind, cone, view);
        culled[i] = outside_frustum(b) ? 1 : 0;
    }
}

PATCHCULL_DISPLACED_CLONES
void cull_displaced_occlusion(const PatchBatchView& patches, const DisplacementRange* ranges, DisplacedBoundKind kind,
                              NormalConeKind cone, const DisplacedCullView& view, const HiZPyramid& hiz,
                              std::uint8_t* decision) {
    check_hiz_convention(hiz, view.depth, "cull_displaced_occlusion");
    for (std::size_t i = 0; i < patches.count; ++i) {
        const DisplacedBound b =
            bound_of(gather(patches, i), ranges ? ranges[i] : DisplacementRange{}, kind, cone, view);
        decision[i] = hiz_decision(b, hiz);
    }
}

}  // namespace patchcull
