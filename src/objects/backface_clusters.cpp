// Clustered back-face culling (Johannsen & Carter 1998) and its hierarchy, as G. Zachmann's
// lecture "Advanced Visibility Computations" presents them (patchcull/objects/backface_clusters.h); the
// patch clusters are in patch_clusters.cpp.
//
// Derivations (the lecture's formulas are garbled in the extracted text; redone here):
//
// Back test. For members (n_i, p_i) and x = e - c:
//   max_i n_i . (e - p_i) = max_i [n_i . x - n_i . (p_i - c)] <= max_i n_i . x - min_i n_i . (p_i - c)
//   max_i n_i . x <= sum_a max_i n_ia x_a = sum_a (x_a > 0 ? max_i n_ia : min_i n_ia) x_a = f(x).
// f is convex and positively homogeneous (f(t x) = t f(x), t >= 0), hence subadditive.
//
// Moving a cluster to other local coordinates c' (merge): n_i . (p_i - c') = n_i . (p_i - c) +
// n_i . (c - c') >= d - f(c' - c)... precisely n_i . (c - c') >= -max_i n_i . (c' - c) >= -f(c' - c),
// so d' = d - f(c' - c) is a valid d for c'. If the merged test f^(e - c') <= d^ <= d' holds, then
// f(e - c) <= f(e - c') + f(c' - c) <= f^(e - c') + f(c' - c) <= d (f <= f^ as the merged box
// holds the child's): the child's own test holds too. Front: g(x) = -f(-x) is superadditive,
// D' = D + f(c - c'), and g(e - c) >= g(e - c') + g(c' - c) = g(e - c') - f(c - c') > D' - f(c - c') = D.
//
// Float test margin: x = fl(e - c) has |x - x*| <= u |x|, and f is Lipschitz with constants
// M_a = max(|n_a|, |m_a|), so |f(x) - f(x*)| <= u sum M_a |x_a|; the three products and three sums
// of fl(f(x) - d) err by <= ~4u (sum M_a |x_a| + |d|). 8u of the same (computed with <= 5u
// relative error) bounds the total; underflow adds at most a few half denorm_min.
//
// Culling probability: the culling volume is {c + x : f(x) <= d}; in the octant with sign
// vector s it is {x : s_a x_a >= 0, sum_a k_a x_a <= d}, k_a = (s_a > 0 ? m_a : n_a). Its
// intersection with U - c is a box cut by one half-space; with x = l + L t (t in [0,1]^3),
// b = k L (negative b flipped by t -> 1 - t) and d'' = d - k . l (adjusted for flips):
//   Vol = prod L * sum_{S subset K} (-1)^|S| max(0, d'' - sum_{a in S} b_a)^|K| / (|K|! prod_K b_a),
// K the axes with b_a != 0 (the others only scale by L_a).
//
// Merge criterion: T(X) = tC + (1 - P(X)) R(X), R(X) = n_X r. T(C) < T(A) + T(B) <=>
//   tC + (1 - P_C)(R_A + R_B) < 2 tC + (1 - P_A) R_A + (1 - P_B) R_B
//   <=> -P_C (R_A + R_B) < tC - P_A R_A - P_B R_B
//   <=> P_C > (P_A n_A + P_B n_B - tC / r) / (n_A + n_B).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <queue>
#include <string>

#include "patchcull/core/error.h"
#include "patchcull/objects/backface_clusters.h"

namespace patchcull {

namespace {

constexpr float kU = 5.9604645e-8f;  // 2^-24
constexpr float kTestMargin = 8 * kU;
constexpr float kTinyMargin = 16 * std::numeric_limits<float>::denorm_min();
constexpr double kPlaneSlack = 1e-14;  // relative rounding slack of double plane values
constexpr float kFltMax = std::numeric_limits<float>::max();

float round_down(double x) {
    if (std::isnan(x)) return -std::numeric_limits<float>::infinity();
    if (x >= double(kFltMax)) return kFltMax;
    float f = static_cast<float>(x);
    if (double(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    return f;
}

float round_up(double x) {
    if (std::isnan(x)) return std::numeric_limits<float>::infinity();
    if (x <= -double(kFltMax)) return -kFltMax;
    float f = static_cast<float>(x);
    if (double(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return f;
}

double get(Vec3 v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }

Vec3 corner(const Bounds& b, int k) {
    return {(k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y, (k & 4) ? b.max.z : b.min.z};
}

// The 9 candidates for c: centre, then the 8 corners.
Vec3 candidate(const Bounds& b, int k) { return k == 0 ? b.center() : corner(b, k - 1); }

// f(y) of a float cluster in double, and a bound on its rounding.
double f_of(const BackfaceCluster& cl, const double y[3], double& slack) {
    double s = 0, mag = 0;
    for (int a = 0; a < 3; ++a) {
        const double k = y[a] > 0 ? get(cl.m_max, a) : get(cl.n_min, a);
        s += k * y[a];
        mag += std::max(std::fabs(get(cl.n_min, a)), std::fabs(get(cl.m_max, a))) * std::fabs(y[a]);
    }
    slack = 1e-15 * mag;
    return s;
}

Bounds union_box(const Bounds& a, const Bounds& b) {
    return {{std::min(a.min.x, b.min.x), std::min(a.min.y, b.min.y), std::min(a.min.z, b.min.z)},
            {std::max(a.max.x, b.max.x), std::max(a.max.y, b.max.y), std::max(a.max.z, b.max.z)}};
}

bool box_finite(const Bounds& b) { return is_finite(b.min) && is_finite(b.max); }

void make_invalid(BackfaceCluster& c) {
    c.n_min = c.m_max = {};
    c.d = -std::numeric_limits<float>::infinity();
    c.d_front = std::numeric_limits<float>::infinity();
}

bool is_invalid(const BackfaceCluster& c) { return !(c.d >= -kFltMax) || !(c.d_front <= kFltMax); }

// Volume of {t in [0,1]^3 : b . t <= d} times nothing (unit box), b any signs.
double unit_box_halfspace(double b[3], double d) {
    for (int a = 0; a < 3; ++a)
        if (b[a] < 0) {
            d -= b[a];
            b[a] = -b[a];
        }
    const double bmax = std::max({b[0], b[1], b[2]});
    if (!(bmax > 0)) return d >= 0 ? 1.0 : 0.0;
    double k[3];
    int n = 0;
    double sum = 0;
    for (int a = 0; a < 3; ++a)
        if (b[a] >= 1e-5 * bmax) {
            k[n++] = b[a];
            sum += b[a];
        }
    if (d <= 0) return 0.0;
    if (d >= sum) return 1.0;
    double prod = 1;
    for (int a = 0; a < n; ++a) prod *= k[a];
    const double fact = n == 1 ? 1 : (n == 2 ? 2 : 6);
    double v = 0;
    for (int mask = 0; mask < (1 << n); ++mask) {
        double r = d;
        int bits = 0;
        for (int a = 0; a < n; ++a)
            if (mask & (1 << a)) r -= k[a], ++bits;
        if (r <= 0) continue;
        const double t = std::pow(r, n);
        v += (bits % 2) ? -t : t;
    }
    return std::clamp(v / (fact * prod), 0.0, 1.0);
}

}  // namespace

// ---- clusters ------------------------------------------------------------------------------

BackfaceCluster make_cluster_from_planes(const ClusterPlane* planes, std::size_t n, const Bounds& box,
                                         std::uint32_t first, std::uint32_t count, bool valid) {
    BackfaceCluster cl;
    cl.first = first;
    cl.count = count;
    cl.box = box;
    if (!valid || !box_finite(box)) {
        cl.c = box_finite(box) ? box.center() : Vec3{};
        make_invalid(cl);
        return cl;
    }
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (std::size_t i = 0; i < n; ++i) {
        const ClusterPlane& p = planes[i];
        for (int a = 0; a < 3; ++a) {
            const double l = p.n[a] - p.en, h = p.n[a] + p.en;
            lo[a] = i == 0 ? l : std::min(lo[a], l);
            hi[a] = i == 0 ? h : std::max(hi[a], h);
        }
    }
    // d(c) and D(c) for each candidate c; keep the largest d.
    double best_d = -std::numeric_limits<double>::infinity(), best_D = 0;
    Vec3 best_c = box.center();
    for (int k = 0; k < 9; ++k) {
        const Vec3 c = candidate(box, k);
        double d = std::numeric_limits<double>::infinity(), D = -std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < n; ++i) {
            const ClusterPlane& p = planes[i];
            const double y[3] = {double(c.x) - p.o.x, double(c.y) - p.o.y, double(c.z) - p.o.z};
            const double v = p.a - (p.n[0] * y[0] + p.n[1] * y[1] + p.n[2] * y[2]);
            const double l1 = std::fabs(y[0]) + std::fabs(y[1]) + std::fabs(y[2]);
            const double mag =
                std::fabs(p.a) + std::fabs(p.n[0] * y[0]) + std::fabs(p.n[1] * y[1]) + std::fabs(p.n[2] * y[2]);
            const double err = p.en * l1 + p.ea + kPlaneSlack * mag;
            d = std::min(d, v - err);
            D = std::max(D, v + err);
        }
        if (n == 0) d = D = double(kFltMax);
        if (d > best_d) best_d = d, best_D = D, best_c = c;
    }
    cl.n_min = {round_down(lo[0]), round_down(lo[1]), round_down(lo[2])};
    cl.m_max = {round_up(hi[0]), round_up(hi[1]), round_up(hi[2])};
    cl.c = best_c;
    cl.d = round_down(best_d);
    cl.d_front = round_up(best_D);
    if (!is_finite(cl.n_min) || !is_finite(cl.m_max) || !std::isfinite(best_d) || !std::isfinite(best_D))
        make_invalid(cl);
    return cl;
}

namespace {

// Triangle t's plane: unit normal (double) with error bounds; false when its vertices are not
// finite. degenerate: two equal vertices (zero area: skipped as a plane).
bool triangle_plane(const Vec3* vertices, const std::uint32_t* indices, std::size_t t, ClusterPlane& out,
                    bool& degenerate) {
    const Vec3 p0 = vertices[indices[3 * t]], p1 = vertices[indices[3 * t + 1]], p2 = vertices[indices[3 * t + 2]];
    if (!is_finite(p0) || !is_finite(p1) || !is_finite(p2)) return false;
    auto same = [](Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
    degenerate = same(p0, p1) || same(p0, p2) || same(p1, p2);
    const double e1[3] = {double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z};
    const double e2[3] = {double(p2.x) - p0.x, double(p2.y) - p0.y, double(p2.z) - p0.z};
    double n[3], err = 0;
    for (int k = 0; k < 3; ++k) {
        const int b = (k + 1) % 3, c = (k + 2) % 3;
        n[k] = e1[b] * e2[c] - e1[c] * e2[b];
        err = std::max(err, 1e-15 * (std::fabs(e1[b] * e2[c]) + std::fabs(e1[c] * e2[b])));
    }
    // Any positive scale keeps each member's sign: unit normals make the bounds of different
    // triangles comparable. Slivers (|n| below 1e-3 of |e1| |e2|, whose normal direction is
    // rounding noise) are scaled as if their normal had that length, so they stay short instead
    // of widening the normal box to every direction. The scaled error: s err plus the scaling's
    // own rounding.
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double l1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    const double l2 = std::sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]);
    const double ref = std::max(len, 1e-3 * l1 * l2);
    const double s = ref > 0 ? 1.0 / ref : 1.0;
    for (int k = 0; k < 3; ++k) out.n[k] = n[k] * s;
    out.en = err * s + 3e-16;
    out.a = 0;
    out.ea = 0;
    out.o = p0;
    return true;
}

Bounds triangle_box(const Vec3* vertices, const std::uint32_t* indices, std::uint32_t first, std::uint32_t count) {
    Bounds b{vertices[indices[3 * std::size_t(first)]], vertices[indices[3 * std::size_t(first)]]};
    for (std::size_t t = first; t < std::size_t(first) + count; ++t)
        for (int k = 0; k < 3; ++k) {
            const Vec3 p = vertices[indices[3 * t + k]];
            b.min = {std::min(b.min.x, p.x), std::min(b.min.y, p.y), std::min(b.min.z, p.z)};
            b.max = {std::max(b.max.x, p.x), std::max(b.max.y, p.y), std::max(b.max.z, p.z)};
        }
    return b;
}

}  // namespace

BackfaceCluster make_triangle_cluster(const Vec3* vertices, const std::uint32_t* indices, std::uint32_t first_triangle,
                                      std::uint32_t count) {
    std::vector<ClusterPlane> planes;
    planes.reserve(count);
    bool valid = true;
    for (std::size_t t = first_triangle; t < std::size_t(first_triangle) + count; ++t) {
        ClusterPlane p;
        bool degenerate = false;
        if (!triangle_plane(vertices, indices, t, p, degenerate)) {
            valid = false;
            break;
        }
        if (!degenerate) planes.push_back(p);
    }
    return make_cluster_from_planes(planes.data(), planes.size(),
                                    triangle_box(vertices, indices, first_triangle, count), first_triangle, count,
                                    valid);
}

double triangle_cluster_d(const Vec3* vertices, const std::uint32_t* indices, std::uint32_t first_triangle,
                          std::uint32_t count, Vec3 c) {
    std::vector<ClusterPlane> planes;
    for (std::size_t t = first_triangle; t < std::size_t(first_triangle) + count; ++t) {
        ClusterPlane p;
        bool degenerate = false;
        if (!triangle_plane(vertices, indices, t, p, degenerate)) return -std::numeric_limits<double>::infinity();
        if (!degenerate) planes.push_back(p);
    }
    // The single-candidate version of make_cluster_from_planes: box = the point c.
    const Bounds box{c, c};
    if (planes.empty()) return double(kFltMax);
    double d = std::numeric_limits<double>::infinity();
    for (const ClusterPlane& p : planes) {
        const double y[3] = {double(c.x) - p.o.x, double(c.y) - p.o.y, double(c.z) - p.o.z};
        const double v = p.a - (p.n[0] * y[0] + p.n[1] * y[1] + p.n[2] * y[2]);
        const double l1 = std::fabs(y[0]) + std::fabs(y[1]) + std::fabs(y[2]);
        const double mag =
            std::fabs(p.a) + std::fabs(p.n[0] * y[0]) + std::fabs(p.n[1] * y[1]) + std::fabs(p.n[2] * y[2]);
        d = std::min(d, v - (p.en * l1 + p.ea + kPlaneSlack * mag));
    }
    (void)box;
    return d;
}

bool cluster_backfacing(const BackfaceCluster& cl, Vec3 eye) {
    const float x[3] = {eye.x - cl.c.x, eye.y - cl.c.y, eye.z - cl.c.z};
    const float n[3] = {cl.n_min.x, cl.n_min.y, cl.n_min.z}, m[3] = {cl.m_max.x, cl.m_max.y, cl.m_max.z};
    float s = 0, mag = std::fabs(cl.d);
    for (int a = 0; a < 3; ++a) {
        s += (x[a] > 0 ? m[a] : n[a]) * x[a];
        mag += std::max(std::fabs(n[a]), std::fabs(m[a])) * std::fabs(x[a]);
    }
    const float v = s - cl.d;
    const float margin = kTestMargin * mag + kTinyMargin;
    return v <= -margin && margin <= kFltMax;
}

bool cluster_frontfacing(const BackfaceCluster& cl, Vec3 eye) {
    const float x[3] = {eye.x - cl.c.x, eye.y - cl.c.y, eye.z - cl.c.z};
    const float n[3] = {cl.n_min.x, cl.n_min.y, cl.n_min.z}, m[3] = {cl.m_max.x, cl.m_max.y, cl.m_max.z};
    float s = 0, mag = std::fabs(cl.d_front);
    for (int a = 0; a < 3; ++a) {
        s += (x[a] > 0 ? n[a] : m[a]) * x[a];
        mag += std::max(std::fabs(n[a]), std::fabs(m[a])) * std::fabs(x[a]);
    }
    const float v = s - cl.d_front;
    const float margin = kTestMargin * mag + kTinyMargin;
    return v > margin && margin <= kFltMax;
}

BackfaceCluster merge_clusters(const BackfaceCluster& a, const BackfaceCluster& b) {
    BackfaceCluster r;
    r.first = std::min(a.first, b.first);
    r.count = a.count + b.count;
    r.box = union_box(a.box, b.box);
    r.n_min = {std::min(a.n_min.x, b.n_min.x), std::min(a.n_min.y, b.n_min.y), std::min(a.n_min.z, b.n_min.z)};
    r.m_max = {std::max(a.m_max.x, b.m_max.x), std::max(a.m_max.y, b.m_max.y), std::max(a.m_max.z, b.m_max.z)};
    if (is_invalid(a) || is_invalid(b) || !box_finite(r.box)) {
        r.c = box_finite(r.box) ? r.box.center() : a.c;
        make_invalid(r);
        return r;
    }
    double best_d = -std::numeric_limits<double>::infinity(), best_D = 0;
    Vec3 best_c = r.box.center();
    for (int k = 0; k < 9; ++k) {
        const Vec3 c = candidate(r.box, k);
        double dd[2], DD[2];
        const BackfaceCluster* ch[2] = {&a, &b};
        for (int i = 0; i < 2; ++i) {
            const BackfaceCluster& x = *ch[i];
            const double fwd[3] = {double(c.x) - x.c.x, double(c.y) - x.c.y, double(c.z) - x.c.z};
            const double back[3] = {-fwd[0], -fwd[1], -fwd[2]};
            double s1 = 0, s2 = 0;
            const double f1 = f_of(x, fwd, s1), f2 = f_of(x, back, s2);
            dd[i] = double(x.d) - f1 - s1 - 1e-15 * std::fabs(double(x.d));
            DD[i] = double(x.d_front) + f2 + s2 + 1e-15 * std::fabs(double(x.d_front));
        }
        const double d = std::min(dd[0], dd[1]);
        if (d > best_d) best_d = d, best_D = std::max(DD[0], DD[1]), best_c = c;
    }
    r.c = best_c;
    r.d = round_down(best_d);
    r.d_front = round_up(best_D);
    if (!std::isfinite(best_d) || !std::isfinite(best_D)) make_invalid(r);
    return r;
}

double culling_probability(const BackfaceCluster& cl, const Bounds& U) {
    const double L[3] = {double(U.max.x) - U.min.x, double(U.max.y) - U.min.y, double(U.max.z) - U.min.z};
    const double vol_u = L[0] * L[1] * L[2];
    if (!(vol_u > 0) || !std::isfinite(vol_u) || is_invalid(cl)) return 0.0;
    const double lo[3] = {double(U.min.x) - cl.c.x, double(U.min.y) - cl.c.y, double(U.min.z) - cl.c.z};
    const double hi[3] = {double(U.max.x) - cl.c.x, double(U.max.y) - cl.c.y, double(U.max.z) - cl.c.z};
    const double n[3] = {cl.n_min.x, cl.n_min.y, cl.n_min.z}, m[3] = {cl.m_max.x, cl.m_max.y, cl.m_max.z};
    double total = 0;
    for (int oct = 0; oct < 8; ++oct) {
        double l[3], h[3], k[3], len[3];
        bool empty = false;
        for (int a = 0; a < 3; ++a) {
            const bool pos = (oct >> a) & 1;
            l[a] = pos ? std::max(lo[a], 0.0) : lo[a];
            h[a] = pos ? hi[a] : std::min(hi[a], 0.0);
            len[a] = h[a] - l[a];
            empty = empty || !(len[a] > 0);
            k[a] = pos ? m[a] : n[a];
        }
        if (empty) continue;
        double b[3];
        double d = cl.d;
        for (int a = 0; a < 3; ++a) {
            b[a] = k[a] * len[a];
            d -= k[a] * l[a];
        }
        total += unit_box_halfspace(b, d) * len[0] * len[1] * len[2];
    }
    return std::clamp(total / vol_u, 0.0, 1.0);
}

bool merge_pays(double p_merged, double p_a, std::size_t n_a, double p_b, std::size_t n_b, double tc_over_r) {
    const double n = double(n_a) + double(n_b);
    if (!(n > 0)) return false;
    return p_merged * n > p_a * double(n_a) + p_b * double(n_b) - tc_over_r;
}

// ---- hierarchy -----------------------------------------------------------------------------

namespace {

const Bounds& viewpoint_box(const ClusterBuildOptions& options, const Bounds& fallback) {
    const Bounds& v = options.viewpoints;
    return (v.min.x <= v.max.x && v.min.y <= v.max.y && v.min.z <= v.max.z) ? v : fallback;
}

// Greedy bottom-up merging of adjacent nodes (a doubly linked list of the current roots): always
// the pair with the largest gain T(A) + T(B) - T(C) (in units of r) among those where merge_pays
// holds and the merged member count is <= max_count. Returns every node created (units first);
// roots: the final roots in range order.
struct MergeNode {
    BackfaceCluster c;
    double p = 0;
    std::int64_t left = -1, right = -1;
    std::uint32_t size = 1, leaves = 1;
};

std::vector<MergeNode> merge_adjacent(const std::vector<BackfaceCluster>& units, const Bounds& U, double tcr,
                                      std::uint64_t max_count, std::vector<std::int64_t>& roots) {
    std::vector<MergeNode> t;
    roots.clear();
    if (units.empty()) return t;
    t.reserve(2 * units.size());
    for (const BackfaceCluster& c : units) {
        MergeNode m;
        m.c = c;
        m.p = culling_probability(c, U);
        t.push_back(m);
    }
    const std::size_t L = units.size();
    std::vector<std::int64_t> prev(2 * L, -1), next(2 * L, -1);
    std::vector<std::uint32_t> version(2 * L, 0);
    std::vector<char> alive(2 * L, 0);
    for (std::size_t i = 0; i < L; ++i) {
        prev[i] = i == 0 ? -1 : std::int64_t(i) - 1;
        next[i] = i + 1 < L ? std::int64_t(i) + 1 : -1;
        alive[i] = 1;
    }
    struct Cand {
        double gain;
        std::int64_t left, right;
        std::uint32_t vl, vr;
        bool operator<(const Cand& o) const { return gain < o.gain || (gain == o.gain && left > o.left); }
    };
    std::priority_queue<Cand> queue;
    auto consider = [&](std::int64_t a, std::int64_t b) {
        if (a < 0 || b < 0) return;
        if (std::uint64_t(t[a].c.count) + t[b].c.count > max_count) return;
        const BackfaceCluster m = merge_clusters(t[a].c, t[b].c);
        const double pm = culling_probability(m, U);
        const double na = t[a].c.count, nb = t[b].c.count;
        if (!merge_pays(pm, t[a].p, t[a].c.count, t[b].p, t[b].c.count, tcr)) return;
        const double gain = tcr + (1 - t[a].p) * na + (1 - t[b].p) * nb - (1 - pm) * (na + nb);
        queue.push({gain, a, b, version[a], version[b]});
    };
    for (std::size_t i = 0; i + 1 < L; ++i) consider(std::int64_t(i), std::int64_t(i) + 1);
    while (!queue.empty()) {
        const Cand c = queue.top();
        queue.pop();
        if (!alive[c.left] || !alive[c.right] || version[c.left] != c.vl || version[c.right] != c.vr ||
            next[c.left] != c.right)
            continue;
        MergeNode m;
        m.c = merge_clusters(t[c.left].c, t[c.right].c);
        m.p = culling_probability(m.c, U);
        m.left = c.left;
        m.right = c.right;
        m.size = 1 + t[c.left].size + t[c.right].size;
        m.leaves = t[c.left].leaves + t[c.right].leaves;
        const std::int64_t id = std::int64_t(t.size());
        t.push_back(m);
        alive[c.left] = alive[c.right] = 0;
        alive[id] = 1;
        prev[id] = prev[c.left];
        next[id] = next[c.right];
        if (prev[id] >= 0) next[prev[id]] = id, ++version[prev[id]];
        if (next[id] >= 0) prev[next[id]] = id, ++version[next[id]];
        consider(prev[id], id);
        consider(id, next[id]);
    }
    std::int64_t head = -1;
    for (std::size_t i = 0; i < t.size(); ++i)
        if (alive[i] && prev[i] < 0) head = std::int64_t(i);
    for (std::int64_t r = head; r >= 0; r = next[r]) roots.push_back(r);
    return t;
}

}  // namespace

std::vector<BackfaceCluster> merge_into_leaves(const std::vector<BackfaceCluster>& units,
                                               const ClusterBuildOptions& options, const Bounds& default_viewpoints) {
    std::vector<std::int64_t> roots;
    const std::vector<MergeNode> t =
        merge_adjacent(units, viewpoint_box(options, default_viewpoints), options.tc_over_r, options.max_leaf, roots);
    std::vector<BackfaceCluster> out;
    out.reserve(roots.size());
    for (std::int64_t r : roots) out.push_back(t[r].c);
    return out;
}

ClusterHierarchy build_cluster_hierarchy(const std::vector<BackfaceCluster>& leaves, const ClusterBuildOptions& options,
                                         const Bounds& default_viewpoints) {
    ClusterHierarchy h;
    std::vector<std::int64_t> roots;
    const std::vector<MergeNode> t =
        merge_adjacent(leaves, viewpoint_box(options, default_viewpoints), options.tc_over_r,
                       std::numeric_limits<std::uint64_t>::max(), roots);
    h.nodes.reserve(t.size());
    std::vector<std::int64_t> stack;
    std::uint32_t leaf_counter = 0;
    for (std::int64_t r : roots) {
        h.roots.push_back(static_cast<std::uint32_t>(h.nodes.size()));
        stack.push_back(r);
        while (!stack.empty()) {
            const std::int64_t id = stack.back();
            stack.pop_back();
            const std::uint32_t index = static_cast<std::uint32_t>(h.nodes.size());
            h.nodes.push_back(t[id].c);
            h.skip.push_back(index + t[id].size);
            h.leaf_begin.push_back(leaf_counter);
            h.leaf_end.push_back(leaf_counter + t[id].leaves);
            if (t[id].left < 0) {
                h.leaves.push_back(index);
                ++leaf_counter;
            } else {
                stack.push_back(t[id].right);
                stack.push_back(t[id].left);
            }
        }
    }
    return h;
}

void cull_cluster_hierarchy(const ClusterHierarchy& h, Vec3 eye, std::uint8_t* leaf_culled,
                            std::uint32_t& cluster_tests) {
    const std::size_t n = h.nodes.size();
    std::size_t i = 0;
    while (i < n) {
        ++cluster_tests;
        const BackfaceCluster& c = h.nodes[i];
        const std::uint32_t lb = h.leaf_begin[i], le = h.leaf_end[i];
        if (cluster_backfacing(c, eye)) {
            std::memset(leaf_culled + lb, 1, le - lb);
            i = h.skip[i];
        } else if (le - lb == 1 || cluster_frontfacing(c, eye)) {
            std::memset(leaf_culled + lb, 0, le - lb);
            i = h.skip[i];
        } else {
            i = i + 1;
        }
    }
}

// ---- triangle clusters ---------------------------------------------------------------------

namespace {

std::uint32_t spread_bits(std::uint32_t v) {
    v &= 0x3ff;
    v = (v | (v << 16)) & 0x030000ff;
    v = (v | (v << 8)) & 0x0300f00f;
    v = (v | (v << 4)) & 0x030c30c3;
    v = (v | (v << 2)) & 0x09249249;
    return v;
}

std::uint32_t morton(Vec3 p, const Bounds& b) {
    auto q = [](float v, float lo, float hi) {
        const float ext = hi - lo;
        const float t = ext > 0 ? (v - lo) / ext : 0.0f;
        return static_cast<std::uint32_t>(std::clamp(t, 0.0f, 1.0f) * 1023.0f);
    };
    if (!is_finite(p)) return 0;
    return spread_bits(q(p.x, b.min.x, b.max.x)) | (spread_bits(q(p.y, b.min.y, b.max.y)) << 1) |
           (spread_bits(q(p.z, b.min.z, b.max.z)) << 2);
}

int cube_face(const double n[3]) {
    const double a0 = std::fabs(n[0]), a1 = std::fabs(n[1]), a2 = std::fabs(n[2]);
    const int a = (a0 >= a1 && a0 >= a2) ? 0 : (a1 >= a2 ? 1 : 2);
    return 2 * a + (n[a] < 0 ? 1 : 0);
}

}  // namespace

Bounds near_field_viewpoints(const Bounds& b) {
    const float side = std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z});
    const float g = side > 0 ? side : 1.0f;
    return {b.min - Vec3{g, g, g}, b.max + Vec3{g, g, g}};
}

ClusterHierarchy build_triangle_clusters(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& indices,
                                         const ClusterBuildOptions& options) {
    if (indices.size() % 3 != 0)
        throw Error("build_triangle_clusters: index count " + std::to_string(indices.size()) +
                    " is not a multiple of 3");
    for (std::uint32_t i : indices)
        if (i >= vertices.size())
            throw Error("build_triangle_clusters: index " + std::to_string(i) + " is past the " +
                        std::to_string(vertices.size()) + " vertices");
    if (options.max_leaf < 1) throw Error("build_triangle_clusters: max_leaf must be >= 1");
    const std::size_t T = indices.size() / 3;
    ClusterHierarchy empty;
    if (T == 0) return empty;
    if (T > 0xffffffffu) throw Error("build_triangle_clusters: too many triangles");

    // Unit normals (zero for zero-area), centroids, bounds.
    std::vector<double> unit(3 * T);
    std::vector<Vec3> centroid(T);
    for (std::size_t t = 0; t < T; ++t) {
        const Vec3 p0 = vertices[indices[3 * t]], p1 = vertices[indices[3 * t + 1]], p2 = vertices[indices[3 * t + 2]];
        const double e1[3] = {double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z};
        const double e2[3] = {double(p2.x) - p0.x, double(p2.y) - p0.y, double(p2.z) - p0.z};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int a = 0; a < 3; ++a) unit[3 * t + a] = len > 0 && std::isfinite(len) ? n[a] / len : 0.0;
        centroid[t] = (p0 + p1 + p2) * (1.0f / 3.0f);
    }
    Bounds all{centroid[0], centroid[0]};
    for (const Vec3& c : centroid)
        if (is_finite(c)) {
            all.min = {std::min(all.min.x, c.x), std::min(all.min.y, c.y), std::min(all.min.z, c.z)};
            all.max = {std::max(all.max.x, c.x), std::max(all.max.y, c.y), std::max(all.max.z, c.z)};
        }
    // Seeds in Morton order.
    std::vector<std::uint32_t> order(T), code(T);
    for (std::size_t t = 0; t < T; ++t) code[t] = morton(centroid[t], all);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return code[a] < code[b]; });
    std::vector<std::uint32_t> rank(T);
    for (std::size_t k = 0; k < T; ++k) rank[order[k]] = static_cast<std::uint32_t>(k);
    // Vertex -> triangles (CSR).
    std::vector<std::uint32_t> vstart(vertices.size() + 1, 0), vtri(indices.size());
    for (std::uint32_t i : indices) ++vstart[i + 1];
    for (std::size_t v = 0; v < vertices.size(); ++v) vstart[v + 1] += vstart[v];
    {
        std::vector<std::uint32_t> fill(vstart.begin(), vstart.end() - 1);
        for (std::size_t k = 0; k < indices.size(); ++k) vtri[fill[indices[k]]++] = static_cast<std::uint32_t>(k / 3);
    }
    const double cos_max = std::cos(options.max_leaf_normal_angle);
    std::vector<char> assigned(T, 0);
    std::vector<std::vector<std::uint32_t>> leaf_tris;
    struct Item {
        double key;
        std::uint32_t t;
        bool operator<(const Item& o) const { return key < o.key || (key == o.key && t > o.t); }
    };
    std::size_t cursor = 0;
    const std::size_t window = 2 * std::size_t(options.max_leaf);
    for (std::size_t k = 0; k < T; ++k) {
        const std::uint32_t seed = order[k];
        if (assigned[seed]) continue;
        std::vector<std::uint32_t> leaf;
        std::priority_queue<Item> frontier;
        const double* sn = &unit[3 * seed];
        const bool seed_zero = sn[0] == 0 && sn[1] == 0 && sn[2] == 0;
        auto key_of = [&](std::uint32_t t) {
            const double* n = &unit[3 * t];
            if (n[0] == 0 && n[1] == 0 && n[2] == 0) return 2.0;  // zero area: joins any leaf
            if (seed_zero) return 1.0;
            return n[0] * sn[0] + n[1] * sn[1] + n[2] * sn[2];
        };
        auto push_neighbours = [&](std::uint32_t t) {
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t v = indices[3 * std::size_t(t) + c];
                for (std::uint32_t q = vstart[v]; q < vstart[v + 1]; ++q)
                    if (!assigned[vtri[q]]) frontier.push({key_of(vtri[q]), vtri[q]});
            }
        };
        assigned[seed] = 1;
        leaf.push_back(seed);
        push_neighbours(seed);
        // Spatial neighbours in Morton order too (meshes without shared vertices).
        for (std::size_t q = rank[seed] + 1; q < T && q <= rank[seed] + window; ++q)
            if (!assigned[order[q]]) frontier.push({key_of(order[q]), order[q]});
        while (leaf.size() < options.max_leaf && !frontier.empty()) {
            const Item it = frontier.top();
            frontier.pop();
            if (assigned[it.t]) continue;
            if (it.key < cos_max) break;
            assigned[it.t] = 1;
            leaf.push_back(it.t);
            push_neighbours(it.t);
        }
        leaf_tris.push_back(std::move(leaf));
        (void)cursor;
    }
    // Leaves ordered by their mean normal's cube face, then Morton order of their first triangle.
    std::vector<std::uint32_t> lorder(leaf_tris.size());
    std::vector<int> lface(leaf_tris.size());
    for (std::size_t l = 0; l < leaf_tris.size(); ++l) {
        double n[3] = {0, 0, 0};
        for (std::uint32_t t : leaf_tris[l])
            for (int a = 0; a < 3; ++a) n[a] += unit[3 * t + a];
        lface[l] = cube_face(n);
    }
    std::iota(lorder.begin(), lorder.end(), 0u);
    std::stable_sort(lorder.begin(), lorder.end(), [&](std::uint32_t a, std::uint32_t b) {
        if (lface[a] != lface[b]) return lface[a] < lface[b];
        return rank[leaf_tris[a][0]] < rank[leaf_tris[b][0]];
    });
    std::vector<std::uint32_t> reordered;
    std::vector<std::uint32_t> tri_order;
    reordered.reserve(indices.size());
    tri_order.reserve(T);
    std::vector<BackfaceCluster> leaves;
    leaves.reserve(leaf_tris.size());
    for (std::uint32_t l : lorder) {
        const std::uint32_t first = static_cast<std::uint32_t>(tri_order.size());
        for (std::uint32_t t : leaf_tris[l]) {
            tri_order.push_back(t);
            for (int c = 0; c < 3; ++c) reordered.push_back(indices[3 * std::size_t(t) + c]);
        }
        leaves.push_back(make_triangle_cluster(vertices.data(), reordered.data(), first,
                                               static_cast<std::uint32_t>(leaf_tris[l].size())));
    }
    // The grown regions as units of the lecture's cluster generation (adjacent ones merged while
    // merge_pays holds, up to max_leaf triangles), each final leaf recomputed from its triangles.
    const Bounds vb = triangle_box(vertices.data(), indices.data(), 0, static_cast<std::uint32_t>(T));
    const Bounds U = near_field_viewpoints(vb);
    const std::vector<BackfaceCluster> merged = merge_into_leaves(leaves, options, U);
    leaves.clear();
    for (const BackfaceCluster& m : merged)
        leaves.push_back(make_triangle_cluster(vertices.data(), reordered.data(), m.first, m.count));
    ClusterHierarchy h = build_cluster_hierarchy(leaves, options, U);
    h.indices = std::move(reordered);
    h.triangle_order = std::move(tri_order);
    return h;
}

ClusterHierarchy build_triangle_clusters(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& indices,
                                         double tc_over_r, std::uint32_t max_leaf_triangles) {
    ClusterBuildOptions o;
    o.tc_over_r = tc_over_r;
    o.max_leaf = max_leaf_triangles;
    return build_triangle_clusters(vertices, indices, o);
}

}  // namespace patchcull
