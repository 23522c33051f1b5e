// Clusters of bicubic patches for clustered back-face culling (patchcull/objects/backface_clusters.h;
// beyond G. Zachmann's lecture "Advanced Visibility Computations"): each patch
// contributes the 64 object-space Bezier control planes of its parametric tangent plane (Loop,
// Niessner & Eisenacher, "Effective Back-Patch Culling for Hardware Tessellation", §3-6), which
// bound every tangent plane of the patch: T(u, v) = sum B7_iu(u) B7_jv(v) t_k with weights >= 0,
// so e . T(u, v) <= max_k e . t_k, and the patch is back-facing (backpatch.h: e . T <= 0 for all
// (u, v)) when every e . t_k <= 0, the cluster test's condition for each plane.
//
// The planes come from the same generated table as the ptp kernels (src/core/ptp_table.inc), in
// double precision and in object space (the kernels use clip-space z components only).
// Rounding bound per term w * cross4(a, b, c), component by component: the 3x3 determinant of
// double coordinates errs by <= ~4 * 2^-53 of its permanent (the same expansion with absolute
// values), the weighted sum of up to 33 terms by <= 33 * 2^-53 of the sum of |w| * permanents:
// 1e-14 |w| perm covers both. The local coordinates x - o w round once (<= 2^-53 of their size):
// a perturbation delta of the 9 entries moves the determinant by <= 9 * 2 R^2 delta (R the
// largest local coordinate, weights included), hence + 20 R^2 delta per term.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/objects/backface_clusters.h"

namespace patchcull {

namespace {

struct TableRow {
    int dest, j, k, l;
    long long num, den;
};

constexpr TableRow kTable[] = {
#include "core/ptp_table.inc"
};
static_assert(sizeof(kTable) / sizeof(kTable[0]) == 516, "Loop, Niessner & Eisenacher: 516 weighted cross4 products");

double det3(double a0, double a1, double a2, double b0, double b1, double b2, double c0, double c1, double c2) {
    return a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0);
}

double perm3(double a0, double a1, double a2, double b0, double b1, double b2, double c0, double c1, double c2) {
    return std::fabs(a0) * (std::fabs(b1 * c2) + std::fabs(b2 * c1)) +
           std::fabs(a1) * (std::fabs(b0 * c2) + std::fabs(b2 * c0)) +
           std::fabs(a2) * (std::fabs(b0 * c1) + std::fabs(b1 * c0));
}

bool same_point(const Vec4& a, const Vec4& b) { return a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w; }

}  // namespace

void patch_control_planes(const BezierPatch& patch, Vec3 origin, PlaneD planes[64], PlaneD* error) {
    double L[16][4];
    double rxyz = 0, r = 0;
    for (int k = 0; k < 16; ++k) {
        const Vec4 p = patch.cp[k];
        // o * w is exact in double (two floats); the subtraction rounds once.
        L[k][0] = double(p.x) - double(origin.x) * p.w;
        L[k][1] = double(p.y) - double(origin.y) * p.w;
        L[k][2] = double(p.z) - double(origin.z) * p.w;
        L[k][3] = p.w;
        for (int c = 0; c < 3; ++c) rxyz = std::max(rxyz, std::fabs(L[k][c]));
        for (int c = 0; c < 4; ++c) r = std::max(r, std::fabs(L[k][c]));
    }
    const double delta = 1.12e-16 * rxyz;
    const double input_term = 20 * r * r * delta;
    for (int d = 0; d < 64; ++d) {
        planes[d] = {};
        if (error) error[d] = {};
    }
    for (const TableRow& row : kTable) {
        // Two equal control points: cross4 is exactly zero (a collapsed edge's terms).
        if (same_point(patch.cp[row.j], patch.cp[row.k]) || same_point(patch.cp[row.j], patch.cp[row.l]) ||
            same_point(patch.cp[row.k], patch.cp[row.l]))
            continue;
        const double* a = L[row.j];
        const double* b = L[row.k];
        const double* c = L[row.l];
        const double w = double(row.num) / double(row.den);
        // cross4 as in ground_truth.cpp (Loop, Niessner & Eisenacher, Appendix A).
        const double t[4] = {det3(a[1], b[1], c[1], a[2], b[2], c[2], a[3], b[3], c[3]),
                             -det3(a[0], b[0], c[0], a[2], b[2], c[2], a[3], b[3], c[3]),
                             det3(a[0], b[0], c[0], a[1], b[1], c[1], a[3], b[3], c[3]),
                             -det3(a[0], b[0], c[0], a[1], b[1], c[1], a[2], b[2], c[2])};
        PlaneD& out = planes[row.dest];
        out.x += w * t[0];
        out.y += w * t[1];
        out.z += w * t[2];
        out.w += w * t[3];
        if (error) {
            const double p[4] = {perm3(a[1], b[1], c[1], a[2], b[2], c[2], a[3], b[3], c[3]),
                                 perm3(a[0], b[0], c[0], a[2], b[2], c[2], a[3], b[3], c[3]),
                                 perm3(a[0], b[0], c[0], a[1], b[1], c[1], a[3], b[3], c[3]),
                                 perm3(a[0], b[0], c[0], a[1], b[1], c[1], a[2], b[2], c[2])};
            const double aw = std::fabs(w);
            PlaneD& e = error[row.dest];
            e.x += aw * (1e-14 * p[0] + input_term);
            e.y += aw * (1e-14 * p[1] + input_term);
            e.z += aw * (1e-14 * p[2] + input_term);
            e.w += aw * (1e-14 * p[3] + input_term);
        }
    }
}

namespace {

// Appends patch's non-zero control planes (unit normals where the normal is not zero); false
// when a value is not finite.
bool append_patch_planes(const BezierPatch& patch, std::vector<ClusterPlane>& out) {
    const Vec4 p0 = patch.cp[0];
    if (!(p0.w != 0)) return false;
    const Vec3 o{p0.x / p0.w, p0.y / p0.w, p0.z / p0.w};
    if (!is_finite(o)) return false;
    PlaneD planes[64], error[64];
    patch_control_planes(patch, o, planes, error);
    // Unit normals, except that planes whose normal is below 1e-3 of the patch's longest (near a
    // collapsed edge, direction dominated by rounding) are scaled by that reference length so
    // they stay short (any positive scale keeps a plane's side).
    double longest = 0;
    for (int k = 0; k < 64; ++k)
        longest = std::max(
            longest, std::sqrt(planes[k].x * planes[k].x + planes[k].y * planes[k].y + planes[k].z * planes[k].z));
    for (int k = 0; k < 64; ++k) {
        const PlaneD& t = planes[k];
        const PlaneD& e = error[k];
        if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z) || !std::isfinite(t.w) ||
            !std::isfinite(e.x) || !std::isfinite(e.y) || !std::isfinite(e.z) || !std::isfinite(e.w))
            return false;
        if (t.x == 0 && t.y == 0 && t.z == 0 && t.w == 0 && e.x == 0 && e.y == 0 && e.z == 0 && e.w == 0)
            continue;  // exactly zero: faces nothing
        const double len = std::max(std::sqrt(t.x * t.x + t.y * t.y + t.z * t.z), 1e-3 * longest);
        const double s = len > 0 && std::isfinite(len) ? 1.0 / len : 1.0;
        ClusterPlane c;
        c.n[0] = t.x * s;
        c.n[1] = t.y * s;
        c.n[2] = t.z * s;
        c.a = -t.w * s;
        c.o = o;
        c.en = std::max({e.x, e.y, e.z}) * s + 2.3e-16 * (std::fabs(c.n[0]) + std::fabs(c.n[1]) + std::fabs(c.n[2]));
        c.ea = e.w * s + 2.3e-16 * std::fabs(c.a);
        out.push_back(c);
    }
    return true;
}

Bounds control_point_box(const BezierPatch* patches, std::size_t first, std::size_t count, bool& finite) {
    Bounds b{{0, 0, 0}, {0, 0, 0}};
    bool any = false;
    finite = true;
    for (std::size_t p = first; p < first + count; ++p)
        for (const Vec4& cp : patches[p].cp) {
            const Vec3 q = cartesian(cp);
            if (!is_finite(q)) {
                finite = false;
                continue;
            }
            if (!any) b = {q, q}, any = true;
            b.min = {std::min(b.min.x, q.x), std::min(b.min.y, q.y), std::min(b.min.z, q.z)};
            b.max = {std::max(b.max.x, q.x), std::max(b.max.y, q.y), std::max(b.max.z, q.z)};
        }
    return b;
}

}  // namespace

BackfaceCluster make_patch_cluster(const BezierPatch* patches, std::uint32_t first, std::uint32_t count) {
    std::vector<ClusterPlane> planes;
    planes.reserve(64 * std::size_t(count));
    bool valid = true;
    for (std::size_t p = first; p < std::size_t(first) + count && valid; ++p)
        valid = append_patch_planes(patches[p], planes);
    bool finite = true;
    const Bounds box = control_point_box(patches, first, count, finite);
    return make_cluster_from_planes(planes.data(), planes.size(), box, first, count, valid && finite);
}

ClusterHierarchy build_patch_clusters(const BezierPatch* patches, std::size_t n, const ClusterBuildOptions& options) {
    if (options.max_leaf < 1) throw Error("build_patch_clusters: max_leaf must be >= 1");
    if (n > 0xffffffffu) throw Error("build_patch_clusters: too many patches");
    ClusterHierarchy h;
    if (n == 0) return h;
    // Single patches as units of the lecture's cluster generation (adjacent ones merged while
    // merge_pays holds, up to max_leaf patches), each final leaf recomputed from its patches.
    bool finite = true;
    const Bounds all = control_point_box(patches, 0, n, finite);
    const Bounds U = near_field_viewpoints(all);
    std::vector<BackfaceCluster> units;
    units.reserve(n);
    for (std::size_t p = 0; p < n; ++p) units.push_back(make_patch_cluster(patches, static_cast<std::uint32_t>(p), 1));
    std::vector<BackfaceCluster> leaves;
    for (const BackfaceCluster& m : merge_into_leaves(units, options, U))
        leaves.push_back(make_patch_cluster(patches, m.first, m.count));
    return build_cluster_hierarchy(leaves, options, U);
}

ClusterHierarchy build_patch_clusters(const BezierPatch* patches, std::size_t n, double tc_over_r,
                                      std::uint32_t max_leaf_patches) {
    ClusterBuildOptions o;
    o.tc_over_r = tc_over_r;
    o.max_leaf = max_leaf_patches;
    return build_patch_clusters(patches, n, o);
}

}  // namespace patchcull
