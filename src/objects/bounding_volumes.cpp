// Bounding volumes and their frustum tests (patchcull/objects/bounding_volumes.h): enclosing volumes,
// single-volume tests with plane masking and coherence, the scalar batch references, meta-BVs
// and detail culling, after G. Zachmann, "Advanced Visibility Computations".
// The SIMD batch kernels live in bounding_volumes_simd.cpp.
//
// Bit-exact agreement with the SIMD kernels rests on the rules of frustum.cpp: every multiply-add
// is an explicit std::fma (the build passes -ffp-contract=off), max is `a > b ? a : b` (x86
// maxps), and each value is computed by the same operations in the same order. The per-plane
// and per-volume terms (both files):
//   plane k:  pthr = fma(eps, |w|, 1e-30), nthr = -pthr, nlen = -len      (eps = 1e-6)
//   value:    v(X, Y, Z) = fma(z, Z, fma(y, Y, fma(x, X, w)))
//   sphere:   M = max(max(|cx|, |cy|), |cz|),  g = fma(eps, (M + M) + r, r)
//             outside_k: fma(len, g, v(c)) < nthr;  inside_k: fma(nlen, g, v(c)) > pthr
//   AABB:     M = max of the six |coordinates| (min.x, min.y, min.z, max.x, max.y, max.z),
//             fin = (((((min.x + min.y) + min.z) + max.x) + max.y) + max.z) * 0 (NaN for a NaN or
//             infinite coordinate, else +-0), g = eps * (M + M) + fin; p-vertex P_a = (x_a >= 0 ? max_a : min_a),
//             n-vertex the other outside_k: fma(len, g, v(P)) < nthr;  inside_k: fma(nlen, g, v(N)) > pthr
//   OBB:      M as the sphere's, H = (h0 + h1) + h2, s = M + H, g = eps * (s + s),
//             d_i = fma(z, a_i.z, fma(y, a_i.y, x * a_i.x)),
//             e = fma(h2, |d2|, fma(h1, |d1|, h0 * |d0|)), hi = v(c) + e, lo = v(c) - e
//             outside_k: fma(len, g, hi) < nthr;  inside_k: fma(nlen, g, lo) > pthr
//   outside = empty or any outside_k; inside = every inside_k (and not outside).
//
// Why this is conservative (the bound behind kVolumeRelativeEpsilon). Let R be the exact plane
// of the float matrix (the ground truth evaluates it in double), R~ the stored float row
// (|R~ - R| <= u |R~| per element, u = 2^-24), len = fl(|R~.xyz|) >= (1 - 2u) |R.xyz|. For the
// centre c, |v(c) - R . (c, 1)| <= 4u (|x cx| + |y cy| + |z cz| + |w|) + O(u^2) (three fmas, one
// rounding each, plus the row's own rounding), and |x cx| + |y cy| + |z cz| <= sqrt(3) |R.xyz| M.
// The largest exact value over the sphere is R . (c, 1) + |R.xyz| r, at most
// v(c) + |R.xyz| (r + 4 sqrt(3) u M) + 4u |w|, which is below v(c) + len g + pthr because
// eps = 1e-6 > 16u covers 4 sqrt(3) u M <= 2 eps M (with the roundings of g, len and the final
// fma, all relative u) and 4u |w| <= eps |w|. So "outside_k" implies every exact value is < 0;
// inside_k is the mirror image. For the AABB the p-vertex is a float point of the box (r = 0,
// M its coordinates' bound); for the OBB the error of e is below 6u * sqrt(3) |R.xyz| * 1.001 H
// (|a_i| <= 1.001), covered by eps * 2H. 1e-30 covers underflowing products (absolute error
// 2^-149 each).
//
// classify_aabb_corners returns classify_aabb's answer: v is monotone in each coordinate in
// float too (fma(x, X, w) is non-decreasing in X for x >= 0 and non-increasing for x < 0, every
// later fma is non-decreasing in its addend, rounding is monotone), so the largest of the eight
// computed corner values is the computed p-vertex value, bit for bit, and the smallest the
// n-vertex value.
#include "patchcull/objects/bounding_volumes.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/scalar_clones.h"
// The templates below must be inlined into each clone, or the FMA clone would call a shared
// non-FMA copy that calls libm's fmaf.
#if defined(__GNUC__) || defined(__clang__)
#define PATCHCULL_INLINE inline __attribute__((always_inline))
#else
#define PATCHCULL_INLINE inline
#endif

namespace patchcull {
namespace {

constexpr float kEps = kVolumeRelativeEpsilon;
constexpr float kTiny = 1e-30f;
constexpr float kInf = std::numeric_limits<float>::infinity();

inline float max_like_simd(float a, float b) { return a > b ? a : b; }

struct PlaneConst {
    float x, y, z, w, len, nlen, pthr, nthr;
};

PATCHCULL_INLINE PlaneConst plane_const(const FrustumPlanes& planes, int k) {
    PlaneConst p;
    p.x = planes.rows[k].x;
    p.y = planes.rows[k].y;
    p.z = planes.rows[k].z;
    p.w = planes.rows[k].w;
    p.len = planes.normal_length[k];
    p.nlen = -p.len;
    p.pthr = std::fma(kEps, std::fabs(p.w), kTiny);
    p.nthr = -p.pthr;
    return p;
}

PATCHCULL_INLINE float plane_value(const PlaneConst& p, float X, float Y, float Z) {
    return std::fma(p.z, Z, std::fma(p.y, Y, std::fma(p.x, X, p.w)));
}

// -1: outside the plane, 1: inside it, 0: straddles it.
PATCHCULL_INLINE int plane_side(const PlaneConst& p, float g, float hi, float lo) {
    if (std::fma(p.len, g, hi) < p.nthr) return -1;
    if (std::fma(p.nlen, g, lo) > p.pthr) return 1;
    return 0;
}

// ---- per-volume terms (the file comment's formulas) ----

inline bool empty(const Sphere& s) { return s.radius < 0; }
inline bool empty(const Bounds& b) { return b.min.x > b.max.x || b.min.y > b.max.y || b.min.z > b.max.z; }
inline bool empty(const Obb& b) { return b.half_extents[0] < 0; }

struct SphereTerms {
    float g;
    const Sphere* s;
    PATCHCULL_INLINE SphereTerms(const Sphere& sphere) : s(&sphere) {
        const Vec3 c = sphere.center;
        const float m = max_like_simd(max_like_simd(std::fabs(c.x), std::fabs(c.y)), std::fabs(c.z));
        g = std::fma(kEps, (m + m) + sphere.radius, sphere.radius);
    }
    PATCHCULL_INLINE int side(const PlaneConst& p) const {
        const float v = plane_value(p, s->center.x, s->center.y, s->center.z);
        return plane_side(p, g, v, v);
    }
};

struct AabbTerms {
    float g;
    const Bounds* b;
    PATCHCULL_INLINE AabbTerms(const Bounds& box) : b(&box) {
        float m = std::fabs(box.min.x);
        m = max_like_simd(m, std::fabs(box.min.y));
        m = max_like_simd(m, std::fabs(box.min.z));
        m = max_like_simd(m, std::fabs(box.max.x));
        m = max_like_simd(m, std::fabs(box.max.y));
        m = max_like_simd(m, std::fabs(box.max.z));
        // +-0 for finite boxes, NaN when a coordinate is NaN or infinite (then never outside).
        const float fin = (((((box.min.x + box.min.y) + box.min.z) + box.max.x) + box.max.y) + box.max.z) * 0.0f;
        g = kEps * (m + m) + fin;
    }
    PATCHCULL_INLINE int side(const PlaneConst& p) const {
        const float hi = plane_value(p, p.x >= 0 ? b->max.x : b->min.x, p.y >= 0 ? b->max.y : b->min.y,
                                     p.z >= 0 ? b->max.z : b->min.z);
        const float lo = plane_value(p, p.x >= 0 ? b->min.x : b->max.x, p.y >= 0 ? b->min.y : b->max.y,
                                     p.z >= 0 ? b->min.z : b->max.z);
        return plane_side(p, g, hi, lo);
    }
};

struct CornerTerms {
    float g;
    const Bounds* b;
    PATCHCULL_INLINE CornerTerms(const Bounds& box) : g(AabbTerms(box).g), b(&box) {}
    PATCHCULL_INLINE int side(const PlaneConst& p) const {
        float hi = -kInf, lo = kInf;
        for (int i = 0; i < 8; ++i) {
            const float v = plane_value(p, (i & 1) ? b->max.x : b->min.x, (i & 2) ? b->max.y : b->min.y,
                                        (i & 4) ? b->max.z : b->min.z);
            hi = max_like_simd(hi, v);
            lo = v < lo ? v : lo;
        }
        return plane_side(p, g, hi, lo);
    }
};

struct ObbTerms {
    float g;
    const Obb* b;
    PATCHCULL_INLINE ObbTerms(const Obb& box) : b(&box) {
        const Vec3 c = box.center;
        const float m = max_like_simd(max_like_simd(std::fabs(c.x), std::fabs(c.y)), std::fabs(c.z));
        const float h = (box.half_extents[0] + box.half_extents[1]) + box.half_extents[2];
        const float s = m + h;
        g = kEps * (s + s);
    }
    PATCHCULL_INLINE int side(const PlaneConst& p) const {
        const float v = plane_value(p, b->center.x, b->center.y, b->center.z);
        float d[3];
        for (int i = 0; i < 3; ++i) {
            const Vec3 a = b->axes[i];
            d[i] = std::fabs(std::fma(p.z, a.z, std::fma(p.y, a.y, p.x * a.x)));
        }
        const float e =
            std::fma(b->half_extents[2], d[2], std::fma(b->half_extents[1], d[1], b->half_extents[0] * d[0]));
        return plane_side(p, g, v + e, v - e);
    }
};

template <class Terms, class Volume>
PATCHCULL_INLINE Containment classify_masked(const FrustumPlanes& planes, const Volume& volume, PlaneCullState& state,
                                             std::uint32_t& plane_tests) {
    if (empty(volume)) return Containment::outside;
    const Terms terms(volume);
    std::uint8_t mask = state.plane_mask & 0x3f;
    const int first = state.last_plane;
    auto test = [&](int k) {
        ++plane_tests;
        const int s = terms.side(plane_const(planes, k));
        if (s > 0) mask = static_cast<std::uint8_t>(mask & ~(1u << k));
        return s;
    };
    if (first >= 0 && first < 6 && ((mask >> first) & 1)) {
        if (test(first) < 0) return Containment::outside;
    }
    for (int k = 0; k < 6; ++k) {
        if (k == first || !((mask >> k) & 1)) continue;
        if (test(k) < 0) {
            state.last_plane = static_cast<std::int8_t>(k);
            return Containment::outside;
        }
    }
    state.plane_mask = mask;
    return mask == 0 ? Containment::inside : Containment::intersecting;
}

// All six planes in order, no early exit (the batch kernels' reference).
template <class Terms, class Volume>
PATCHCULL_INLINE Containment classify_all(const PlaneConst pc[6], const Volume& volume) {
    if (empty(volume)) return Containment::outside;
    const Terms terms(volume);
    bool out = false, in = true;
    for (int k = 0; k < 6; ++k) {
        const int s = terms.side(pc[k]);
        out = out || s < 0;
        in = in && s > 0;
    }
    return out ? Containment::outside : in ? Containment::inside : Containment::intersecting;
}

template <class Terms, class Volume>
PATCHCULL_INLINE void classify_batch(const FrustumPlanes& planes, const Volume* v, std::size_t n, Containment* out) {
    PlaneConst pc[6];
    for (int k = 0; k < 6; ++k) pc[k] = plane_const(planes, k);
    for (std::size_t i = 0; i < n; ++i) out[i] = classify_all<Terms>(pc, v[i]);
}

// ---- double helpers ----

struct D3 {
    double x = 0, y = 0, z = 0;
};
inline D3 d3(Vec3 v) { return {v.x, v.y, v.z}; }
inline D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline D3 operator*(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double dotd(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline D3 crossd(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double comp(D3 a, int i) { return i == 0 ? a.x : i == 1 ? a.y : a.z; }

// Nearest float at or above / below d.
inline float round_up(double d) {
    float f = static_cast<float>(d);
    if (static_cast<double>(f) < d) f = std::nextafter(f, kInf);
    return f;
}
inline float round_down(double d) {
    float f = static_cast<float>(d);
    if (static_cast<double>(f) > d) f = std::nextafter(f, -kInf);
    return f;
}
inline Vec3 to_vec3(D3 a) { return {static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z)}; }

// A radius (distance in double) as a float that is certainly not smaller than the exact one:
// the double subtraction, squares, sum and sqrt err by a few 1e-16 relative.
inline float radius_up(double d) { return round_up(d * (1 + 1e-12)); }

Bounds empty_bounds() { return {{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}}; }
Obb empty_obb() {
    Obb o;
    o.half_extents[0] = o.half_extents[1] = o.half_extents[2] = -1;
    return o;
}

// Eigen-decomposition of a symmetric 3x3 matrix (cyclic Jacobi). Columns of v are eigenvectors.
void jacobi3(double a[3][3], double v[3][3], double eig[3]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) v[i][j] = i == j ? 1 : 0;
    for (int sweep = 0; sweep < 50; ++sweep) {
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if (off <= 1e-30 * diag || off == 0) break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (a[p][q] == 0) continue;
                const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
                const double t = (theta >= 0 ? 1 : -1) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
                const double c = 1 / std::sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 3; ++k) {  // A <- A J (columns p, q)
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {  // A <- J^T A (rows p, q)
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    for (int i = 0; i < 3; ++i) eig[i] = a[i][i];
}

// Inverse of a 3x3 matrix given by columns (double); false when singular.
bool invert3(const D3 col[3], double inv[3][3]) {
    const D3 r0 = crossd(col[1], col[2]), r1 = crossd(col[2], col[0]), r2 = crossd(col[0], col[1]);
    const double det = dotd(col[0], r0);
    if (!(std::fabs(det) > 0)) return false;
    const D3 rows[3] = {r0, r1, r2};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) inv[i][j] = comp(rows[i], j) / det;
    return true;
}

double obb_measure(const Obb& o) {
    const double h0 = o.half_extents[0], h1 = o.half_extents[1], h2 = o.half_extents[2];
    return h0 * h1 * h2;
}

}  // namespace

const char* containment_name(Containment c) {
    switch (c) {
        case Containment::outside:
            return "outside";
        case Containment::intersecting:
            return "intersecting";
        case Containment::inside:
            return "inside";
    }
    return "invalid";
}

// ---- enclosing volumes ----------------------------------------------------------------------

Sphere sphere_of_points(const Vec3* points, std::size_t n) {
    if (n == 0) return {{}, -1};
    // Ritter: the farthest point y from points[0], the farthest z from y, then grow over all.
    auto farthest = [&](D3 from) {
        std::size_t best = 0;
        double bd = -1;
        for (std::size_t i = 0; i < n; ++i) {
            const D3 d = d3(points[i]) - from;
            const double dd = dotd(d, d);
            if (dd > bd) bd = dd, best = i;
        }
        return best;
    };
    const D3 y = d3(points[farthest(d3(points[0]))]);
    const D3 z = d3(points[farthest(y)]);
    D3 c = (y + z) * 0.5;
    double r = std::sqrt(dotd(z - y, z - y)) * 0.5;
    for (std::size_t i = 0; i < n; ++i) {
        const D3 d = d3(points[i]) - c;
        const double dist = std::sqrt(dotd(d, d));
        if (dist > r) {
            const double nr = 0.5 * (r + dist);
            c = c + d * ((nr - r) / dist);
            r = nr;
        }
    }
    // The float centre and the exact largest distance from it.
    Sphere s;
    s.center = to_vec3(c);
    const D3 cf = d3(s.center);
    double r2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const D3 d = d3(points[i]) - cf;
        r2 = std::max(r2, dotd(d, d));
    }
    s.radius = radius_up(std::sqrt(r2));
    return s;
}

Bounds aabb_of_points(const Vec3* points, std::size_t n) {
    Bounds b = empty_bounds();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 p = points[i];
        b.min = {std::min(b.min.x, p.x), std::min(b.min.y, p.y), std::min(b.min.z, p.z)};
        b.max = {std::max(b.max.x, p.x), std::max(b.max.y, p.y), std::max(b.max.z, p.z)};
    }
    return b;
}

Obb obb_of_points(const Vec3* points, std::size_t n) {
    if (n == 0) return empty_obb();
    const Obb aabb_box = obb_of_aabb(aabb_of_points(points, n));
    // Mean and covariance in double, relative to the first point (keeps far-away clouds precise).
    const D3 o = d3(points[0]);
    D3 mean{};
    for (std::size_t i = 0; i < n; ++i) mean = mean + (d3(points[i]) - o);
    mean = mean * (1.0 / static_cast<double>(n));
    double cov[3][3] = {};
    for (std::size_t i = 0; i < n; ++i) {
        const D3 d = d3(points[i]) - o - mean;
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) cov[a][b] += comp(d, a) * comp(d, b);
    }
    double v[3][3], eig[3];
    jacobi3(cov, v, eig);
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int a, int b) { return eig[a] > eig[b]; });
    D3 e0{v[0][order[0]], v[1][order[0]], v[2][order[0]]};
    D3 e1{v[0][order[1]], v[1][order[1]], v[2][order[1]]};
    e0 = e0 * (1 / std::sqrt(dotd(e0, e0)));
    e1 = e1 - e0 * dotd(e0, e1);
    const double l1 = std::sqrt(dotd(e1, e1));
    if (!(l1 > 1e-6)) return aabb_box;  // cannot happen for Jacobi's orthogonal columns
    e1 = e1 * (1 / l1);
    const D3 e2 = crossd(e0, e1);
    Obb box;
    box.axes[0] = to_vec3(e0);
    box.axes[1] = to_vec3(e1);
    box.axes[2] = to_vec3(e2);
    D3 cols[3] = {d3(box.axes[0]), d3(box.axes[1]), d3(box.axes[2])};
    double inv[3][3];
    if (!invert3(cols, inv)) return aabb_box;
    auto coords = [&](D3 d, double s[3]) {
        for (int i = 0; i < 3; ++i) s[i] = inv[i][0] * d.x + inv[i][1] * d.y + inv[i][2] * d.z;
    };
    // Extents in the float axes around the first point, then the float centre of the box and the
    // extents again around it (exact solve up to the double rounding, covered by the absolute term).
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (std::size_t i = 0; i < n; ++i) {
        double s[3];
        coords(d3(points[i]) - o, s);
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], s[a]), hi[a] = std::max(hi[a], s[a]);
    }
    D3 mid = o;
    for (int a = 0; a < 3; ++a) mid = mid + cols[a] * (0.5 * (lo[a] + hi[a]));
    box.center = to_vec3(mid);
    const D3 cf = d3(box.center);
    double h[3] = {0, 0, 0}, size2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const D3 d = d3(points[i]) - cf;
        size2 = std::max(size2, dotd(d, d));
        double s[3];
        coords(d, s);
        for (int a = 0; a < 3; ++a) h[a] = std::max(h[a], std::fabs(s[a]));
    }
    const double slack = 1e-12 * std::sqrt(size2);
    for (int a = 0; a < 3; ++a) box.half_extents[a] = round_up(h[a] * (1 + 1e-12) + slack);
    // The smaller of the two boxes (volume; ties, e.g. both flat: the smaller extent sum).
    const double vp = obb_measure(box), va = obb_measure(aabb_box);
    if (va < vp) return aabb_box;
    if (va == vp) {
        const double sp = double(box.half_extents[0]) + box.half_extents[1] + box.half_extents[2];
        const double sa = double(aabb_box.half_extents[0]) + aabb_box.half_extents[1] + aabb_box.half_extents[2];
        if (sa <= sp) return aabb_box;
    }
    return box;
}

Sphere sphere_of_aabb(const Bounds& box) {
    if (empty(box)) return {{}, -1};
    Sphere s;
    s.center = to_vec3((d3(box.min) + d3(box.max)) * 0.5);
    const D3 c = d3(s.center);
    double r2 = 0;
    for (int a = 0; a < 3; ++a) {
        const double e = std::max(comp(d3(box.max), a) - comp(c, a), comp(c, a) - comp(d3(box.min), a));
        r2 += e * e;
    }
    s.radius = radius_up(std::sqrt(r2));
    return s;
}

Obb obb_of_aabb(const Bounds& box) {
    if (empty(box)) return empty_obb();
    Obb o;
    o.center = to_vec3((d3(box.min) + d3(box.max)) * 0.5);
    const D3 c = d3(o.center);
    for (int a = 0; a < 3; ++a)
        o.half_extents[a] = round_up(std::max(comp(d3(box.max), a) - comp(c, a), comp(c, a) - comp(d3(box.min), a)));
    return o;
}

Bounds transformed_aabb(const Bounds& b, const Mat4& m) {
    if (empty(b)) return empty_bounds();
    const D3 c = (d3(b.min) + d3(b.max)) * 0.5, e = (d3(b.max) - d3(b.min)) * 0.5;
    Bounds out;
    float* lo = &out.min.x;
    float* hi = &out.max.x;
    for (int r = 0; r < 3; ++r) {
        const double m0 = m.at(r, 0), m1 = m.at(r, 1), m2 = m.at(r, 2), m3 = m.at(r, 3);
        const double nc = m0 * c.x + m1 * c.y + m2 * c.z + m3;
        const double ne = std::fabs(m0) * e.x + std::fabs(m1) * e.y + std::fabs(m2) * e.z;
        // Double rounding of the sums above: a few 1e-16 of the terms' magnitudes.
        const double slack =
            1e-12 * (std::fabs(m0 * c.x) + std::fabs(m1 * c.y) + std::fabs(m2 * c.z) + std::fabs(m3) + ne);
        lo[r] = round_down(nc - ne - slack);
        hi[r] = round_up(nc + ne + slack);
    }
    return out;
}

Bounds grow_bounds(const Bounds& b, float margin) {
    if (empty(b)) return empty_bounds();
    const double m = margin;
    Bounds out;
    out.min = {round_down(b.min.x - m), round_down(b.min.y - m), round_down(b.min.z - m)};
    out.max = {round_up(b.max.x + m), round_up(b.max.y + m), round_up(b.max.z + m)};
    return out;
}

// ---- frustum tests ------------------------------------------------------------------------------

PATCHCULL_SCALAR_CLONES
Containment classify_sphere(const FrustumPlanes& planes, const Sphere& sphere, PlaneCullState& state,
                            std::uint32_t& plane_tests) {
    return classify_masked<SphereTerms>(planes, sphere, state, plane_tests);
}

PATCHCULL_SCALAR_CLONES
Containment classify_aabb(const FrustumPlanes& planes, const Bounds& box, PlaneCullState& state,
                          std::uint32_t& plane_tests) {
    return classify_masked<AabbTerms>(planes, box, state, plane_tests);
}

PATCHCULL_SCALAR_CLONES
Containment classify_obb(const FrustumPlanes& planes, const Obb& box, PlaneCullState& state,
                         std::uint32_t& plane_tests) {
    return classify_masked<ObbTerms>(planes, box, state, plane_tests);
}

PATCHCULL_SCALAR_CLONES
Containment classify_aabb_corners(const FrustumPlanes& planes, const Bounds& box, std::uint32_t& plane_tests) {
    PlaneCullState fresh;
    return classify_masked<CornerTerms>(planes, box, fresh, plane_tests);
}

PATCHCULL_SCALAR_CLONES
void classify_spheres_scalar(const FrustumPlanes& planes, const Sphere* spheres, std::size_t n, Containment* out) {
    classify_batch<SphereTerms>(planes, spheres, n, out);
}

PATCHCULL_SCALAR_CLONES
void classify_aabbs_scalar(const FrustumPlanes& planes, const Bounds* boxes, std::size_t n, Containment* out) {
    classify_batch<AabbTerms>(planes, boxes, n, out);
}

PATCHCULL_SCALAR_CLONES
void classify_obbs_scalar(const FrustumPlanes& planes, const Obb* boxes, std::size_t n, Containment* out) {
    classify_batch<ObbTerms>(planes, boxes, n, out);
}

// ---- meta-BVs -------------------------------------------------------------------------------------

FrustumMetaBounds frustum_meta_bounds(const Mat4& world_to_clip, ClipDepth depth) {
    FrustumMetaBounds meta;
    meta.box = {{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}};
    meta.sphere = {{}, kInf};
    const Mat4 m = to_zero_to_one(world_to_clip, depth);
    double inv[4][4];
    if (!invert_double(m, inv)) return meta;
    D3 corners[8];
    int sign = 0;
    for (int i = 0; i < 8; ++i) {
        const double ndc[4] = {(i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : 0.0, 1.0};
        double h[4];
        for (int r = 0; r < 4; ++r) {
            h[r] = 0;
            for (int c = 0; c < 4; ++c) h[r] += inv[r][c] * ndc[c];
        }
        const double mag = std::fabs(h[0]) + std::fabs(h[1]) + std::fabs(h[2]);
        // A corner at (or numerically at) infinity: the frustum is unbounded.
        if (!(std::fabs(h[3]) > 1e-9 * mag) || !std::isfinite(mag)) return meta;
        const int s = h[3] > 0 ? 1 : -1;
        if (sign != 0 && s != sign) return meta;
        sign = s;
        corners[i] = {h[0] / h[3], h[1] / h[3], h[2] / h[3]};
    }
    D3 lo = corners[0], hi = corners[0];
    for (int i = 1; i < 8; ++i) {
        lo = {std::min(lo.x, corners[i].x), std::min(lo.y, corners[i].y), std::min(lo.z, corners[i].z)};
        hi = {std::max(hi.x, corners[i].x), std::max(hi.y, corners[i].y), std::max(hi.z, corners[i].z)};
    }
    const double mag = std::max({std::fabs(lo.x), std::fabs(lo.y), std::fabs(lo.z), std::fabs(hi.x), std::fabs(hi.y),
                                 std::fabs(hi.z), hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const double grow = 1e-5 * mag;
    meta.box.min = {round_down(lo.x - grow), round_down(lo.y - grow), round_down(lo.z - grow)};
    meta.box.max = {round_up(hi.x + grow), round_up(hi.y + grow), round_up(hi.z + grow)};
    meta.sphere.center = to_vec3((lo + hi) * 0.5);
    const D3 c = d3(meta.sphere.center);
    double r2 = 0;
    for (const D3& p : corners) r2 = std::max(r2, dotd(p - c, p - c));
    meta.sphere.radius = radius_up(std::sqrt(r2) + grow);
    return meta;
}

namespace {
// Squared distance from p to the box (0 inside); infinite boxes give 0.
double dist2_to_box(D3 p, const Bounds& b) {
    double s = 0;
    for (int a = 0; a < 3; ++a) {
        const double v = comp(p, a), lo = comp(d3(b.min), a), hi = comp(d3(b.max), a);
        const double e = v < lo ? lo - v : v > hi ? v - hi : 0.0;
        s += e * e;
    }
    return s;
}
}  // namespace

bool meta_rejects(const FrustumMetaBounds& meta, const Sphere& sphere) {
    if (empty(sphere)) return true;
    const D3 d = d3(sphere.center) - d3(meta.sphere.center);
    const double rr = double(sphere.radius) + double(meta.sphere.radius);
    if (dotd(d, d) > rr * rr) return true;
    const double r = sphere.radius;
    return dist2_to_box(d3(sphere.center), meta.box) > r * r;
}

bool meta_rejects(const FrustumMetaBounds& meta, const Bounds& box) {
    if (empty(box)) return true;
    if (box.max.x < meta.box.min.x || box.min.x > meta.box.max.x) return true;
    if (box.max.y < meta.box.min.y || box.min.y > meta.box.max.y) return true;
    if (box.max.z < meta.box.min.z || box.min.z > meta.box.max.z) return true;
    const double r = meta.sphere.radius;
    return dist2_to_box(d3(meta.sphere.center), box) > r * r;
}

// ---- detail culling -------------------------------------------------------------------------------

float projection_pixel_scale(float fovy_radians, float viewport_height) {
    return static_cast<float>(viewport_height / (2.0 * std::tan(0.5 * double(fovy_radians))));
}

float projected_radius_pixels(const Sphere& sphere, Vec3 eye, float pixel_scale) {
    const double d = std::sqrt(dotd(d3(sphere.center) - d3(eye), d3(sphere.center) - d3(eye)));
    if (d <= double(sphere.radius)) return kInf;
    return static_cast<float>(double(sphere.radius) * pixel_scale / d);
}

bool detail_culled(const Sphere& sphere, Vec3 eye, float pixel_scale, float min_pixel_area) {
    if (!(min_pixel_area > 0)) return false;
    if (empty(sphere)) return true;
    const double p = projected_radius_pixels(sphere, eye, pixel_scale);
    if (std::isinf(p)) return false;
    return 3.14159265358979323846 * p * p < double(min_pixel_area);
}

}  // namespace patchcull
