// Internal: the scalar reference of the cone constructions and of the back-facing test
// (patchcull/core/cones.h, patchcull/core/backpatch.h). One copy of every formula, inlined into the public
// functions (cones.cpp) and into the scalar kernels (backpatch_cones.cpp); the SIMD kernels
// (backpatch_cones_simd.cpp) repeat it operation by operation. The derivations and the error
// analysis that sets the constants below are in cones.cpp.
//
// Bit-exact rules shared with the SIMD file: every std::fma here is one MulAdd there and every
// other operation is a separately rounded IEEE operation (ISO C++ mode: GCC does not contract);
// min/max are `a < b ? a : b` / `a > b ? a : b` (x86 minps/maxps, Highway Min/Max); sqrt and
// division are the correctly rounded IEEE ones on both sides; the same accumulation order.
#pragma once

#include <cmath>
#include <limits>

#include "patchcull/core/cones.h"

#if defined(__GNUC__)
#define PATCHCULL_CONES_INLINE inline __attribute__((always_inline))
#else
#define PATCHCULL_CONES_INLINE inline
#endif

namespace patchcull::cones_detail {

// ---- constants (see "Floating point" in cones.cpp) --------------------------------------------
/// A control vector with |v|^2 in [kMinLen2, kMaxLen2] is used; |v|^2 == 0 is skipped (zero); any
/// other value (tiny, huge, inf, NaN) makes the cone invalid.
inline constexpr float kMinLen2 = 1e-30f;
inline constexpr float kMaxLen2 = 1e30f;
/// Widening of a control-vector cone in cos space (rounding of normalisation and dot products).
inline constexpr float kCosSlack = 2e-6f;
/// Widening of the Sederberg-Meyers combined cone in sin space.
inline constexpr float kSinSlack = 4e-6f;
/// Rounding bound of a normal-patch control vector: |computed - exact| <= kNormalRoundoff * M,
/// M = sum over its terms of |U'|_1 |V'|_1 (40 u with u = 2^-24 is 2.4e-6).
inline constexpr float kNormalRoundoff = 4e-6f;
/// Sphere radius scale covering the rounding of |p - c| (16 ulp).
inline constexpr float kRadiusScale = 1.0f + 0x1p-20f;
/// Margin of the runtime test in cos space (covers its own rounding, about 2e-6).
inline constexpr float kFacingSlack = 1e-5f;

PATCHCULL_CONES_INLINE float min_like_simd(float a, float b) { return a < b ? a : b; }
PATCHCULL_CONES_INLINE float max_like_simd(float a, float b) { return a > b ? a : b; }

/// x*x + y*y + z*z as mul, fma, fma.
PATCHCULL_CONES_INLINE float dot3(Vec3 a, Vec3 b) { return std::fma(a.z, b.z, std::fma(a.y, b.y, a.x * b.x)); }

/// a x b, each component one mul and one fma: x = fma(a.y, b.z, -(a.z * b.y)), ...
PATCHCULL_CONES_INLINE Vec3 cross3(Vec3 a, Vec3 b) {
    return {std::fma(a.y, b.z, -(a.z * b.y)), std::fma(a.z, b.x, -(a.x * b.z)), std::fma(a.x, b.y, -(a.y * b.x))};
}

PATCHCULL_CONES_INLINE bool is_polynomial(const BezierPatch& p) {
    bool all_one = true;
    for (int k = 0; k < kPatchPoints; ++k) all_one = all_one && p.cp[k].w == 1.0f;
    return all_one;
}

/// Cone of n control vectors: axis = the normalised centre of the box of the normalised non-zero
/// vectors, cos of the half-angle = min over them of axis . v/|v| (minus widen[k] * inv|v_k| when
/// widen is given, the NCONE rounding bound), minus kCosSlack. Unused vectors get h = NaN, which
/// min_like_simd(h, lo) / max_like_simd(h, hi) skip (h first: `NaN < lo` is false, so lo is kept;
/// Highway's Min/Max on every x86 target and its scalar fallbacks keep the non-NaN second operand too). widen == null:
/// zero vectors are skipped; else a zero vector is skipped only when widen[k] == 0 (exactly zero), otherwise the cone
/// is invalid.
template <int n>
PATCHCULL_CONES_INLINE NormalCone cone_of_vectors(const Vec3* v, const float* widen) {
    Vec3 h[n];
    float ratio[n];
    bool used[n];
    bool bad = false;
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
    for (int k = 0; k < n; ++k) {
        const float len2 = dot3(v[k], v[k]);
        const bool nz = len2 >= kMinLen2 && len2 <= kMaxLen2;
        const bool zero_ok = len2 == 0.0f && (widen == nullptr || widen[k] == 0.0f);
        bad = bad || !(nz || zero_ok);
        const float inv = nz ? 1.0f / std::sqrt(len2) : nan;
        h[k] = {v[k].x * inv, v[k].y * inv, v[k].z * inv};
        if (widen) ratio[k] = widen[k] * inv;
        used[k] = nz;
        lo = {min_like_simd(h[k].x, lo.x), min_like_simd(h[k].y, lo.y), min_like_simd(h[k].z, lo.z)};
        hi = {max_like_simd(h[k].x, hi.x), max_like_simd(h[k].y, hi.y), max_like_simd(h[k].z, hi.z)};
    }
    // No used vector: lo + hi = inf - inf = NaN, slen2 NaN, invalid.
    const Vec3 s{(lo.x + hi.x) * 0.5f, (lo.y + hi.y) * 0.5f, (lo.z + hi.z) * 0.5f};
    const float slen2 = dot3(s, s);
    const float sinv = slen2 >= kMinLen2 ? 1.0f / std::sqrt(slen2) : 0.0f;
    const Vec3 axis{s.x * sinv, s.y * sinv, s.z * sinv};
    float cmin = 1.0f;
    for (int k = 0; k < n; ++k) {
        float dk = dot3(axis, h[k]);
        if (widen) dk = dk - ratio[k];
        cmin = min_like_simd(cmin, used[k] ? dk : 1.0f);
    }
    const float c = cmin - kCosSlack;
    NormalCone cone;
    cone.axis = axis;
    cone.cos_angle = c;
    cone.sin_angle = std::sqrt(std::fma(-c, c, 1.0f));
    cone.valid = !bad && slen2 >= kMinLen2 && c > 0.0f;  // some non-zero vector, all within < 90deg
    return cone;
}

/// Control vectors of B_u and B_v without the factor 3: U[3b + a] = P(a+1, b) - P(a, b) (a < 3),
/// V[4d + c] = P(c, d+1) - P(c, d) (d < 3).
PATCHCULL_CONES_INLINE void tangent_vectors(const BezierPatch& p, Vec3 U[12], Vec3 V[12]) {
    for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 3; ++a) {
            const Vec4 p0 = p.cp[4 * b + a], p1 = p.cp[4 * b + a + 1];
            U[3 * b + a] = {p1.x - p0.x, p1.y - p0.y, p1.z - p0.z};
        }
    for (int d = 0; d < 3; ++d)
        for (int c = 0; c < 4; ++c) {
            const Vec4 p0 = p.cp[4 * d + c], p1 = p.cp[4 * d + 4 + c];
            V[4 * d + c] = {p1.x - p0.x, p1.y - p0.y, p1.z - p0.z};
        }
}

/// Sederberg & Meyers: normal cone around a_t x a_b from the tangent cone t and bitangent cone b:
/// sin(alpha_n) = sqrt(s_t^2 + 2 |cos theta| s_t s_b + s_b^2) / sin theta (+ kSinSlack).
PATCHCULL_CONES_INLINE NormalCone combine_cones(const NormalCone& t, const NormalCone& b) {
    const Vec3 nrm = cross3(t.axis, b.axis);
    const float sin2 = dot3(nrm, nrm);
    const float ac = std::fabs(dot3(t.axis, b.axis));
    const float st = t.sin_angle, sb = b.sin_angle;
    float q = st * st;
    q = std::fma((ac + ac) * st, sb, q);
    q = std::fma(sb, sb, q);
    const float sn = std::sqrt(q / sin2) + kSinSlack;
    const float inv = 1.0f / std::sqrt(sin2);
    NormalCone cone;
    cone.axis = {nrm.x * inv, nrm.y * inv, nrm.z * inv};
    cone.sin_angle = sn;
    cone.cos_angle = std::sqrt(std::fma(-sn, sn, 1.0f));
    cone.valid = t.valid && b.valid && sin2 >= kMinLen2 && sn < 1.0f;
    return cone;
}

/// TCONE of a polynomial patch (no w check).
PATCHCULL_CONES_INLINE NormalCone tangent_cone_polynomial(const BezierPatch& p) {
    Vec3 U[12], V[12];
    tangent_vectors(p, U, V);
    const NormalCone t = cone_of_vectors<12>(U, nullptr);
    const NormalCone b = cone_of_vectors<12>(V, nullptr);
    return combine_cones(t, b);
}

/// Gregory patches (patch_source.h's GREGORY_BASIS layout, 20 points g). The surface is the
/// bicubic Bezier patch whose interior points blend the corners' face points:
/// Q11 = (s g3 + t g4) / (s + t), Q21 = (t g8 + (1-s) g9) / (t + 1-s),
/// Q22 = ((1-s) g13 + (1-t) g14) / (2-s-t), Q12 = ((1-t) g18 + s g19) / (1-t + s). Its s-tangent is
/// 3 x a convex combination of the 22 net differences kGregoryNetS (the frozen net's derivative:
/// an interior point's difference lies in the hull of its face points' differences) plus the
/// interior points' own derivatives, c_k(s, t) kGregoryBlendS[k] with 0 <= c_k <= 1/3 inside the
/// patch. So S_s / 3 is a convex combination of the net differences each moved by at most
/// R = (sum of |blend differences|) / 9; likewise S_t. The derivation is in docs/METHODS.md,
/// "Gregory patches".
inline constexpr int kGregoryPoints = 20;
inline constexpr int kGregoryNetVectors = 22;
inline constexpr int kGregoryBlendVectors = 4;
/// {to, from}: the vector g[to] - g[from].
inline constexpr int kGregoryNetS[kGregoryNetVectors][2] = {
    {1, 0}, {7, 1}, {5, 7}, {17, 15}, {11, 17}, {10, 11}, {3, 2},   {4, 2},   {8, 3},   {8, 4},   {9, 3},
    {9, 4}, {6, 8}, {6, 9}, {18, 16}, {19, 16}, {13, 18}, {13, 19}, {14, 18}, {14, 19}, {12, 13}, {12, 14}};
inline constexpr int kGregoryNetT[kGregoryNetVectors][2] = {
    {2, 0},  {16, 2},  {15, 16}, {6, 5}, {12, 6}, {10, 12}, {3, 1},  {4, 1},  {18, 3}, {18, 4},  {19, 3},
    {19, 4}, {17, 18}, {17, 19}, {8, 7}, {9, 7},  {13, 8},  {13, 9}, {14, 8}, {14, 9}, {11, 13}, {11, 14}};
inline constexpr int kGregoryBlendS[kGregoryBlendVectors][2] = {{3, 4}, {8, 9}, {14, 13}, {19, 18}};
inline constexpr int kGregoryBlendT[kGregoryBlendVectors][2] = {{4, 3}, {8, 9}, {13, 14}, {19, 18}};
/// cone_of_vectors' widen for a move of at most R: 2 R covers sin + sin^2 of the angle it turns a
/// vector of length >= R by (docs/METHODS.md); the factor covers the rounding of R.
inline constexpr float kGregoryWidenScale = 2.0f * (1.0f + 0x1p-10f) / 9.0f;

/// The cone of one direction's tangents: net and blend are kGregoryNet* and kGregoryBlend*.
PATCHCULL_CONES_INLINE NormalCone gregory_direction_cone(const Vec3 g[kGregoryPoints],
                                                         const int net[kGregoryNetVectors][2],
                                                         const int blend[kGregoryBlendVectors][2]) {
    const auto diff = [g](const int* pair) {
        const Vec3 a = g[pair[0]], b = g[pair[1]];
        return Vec3{a.x - b.x, a.y - b.y, a.z - b.z};
    };
    float moved = 0.0f;
    for (int k = 0; k < kGregoryBlendVectors; ++k) {
        const Vec3 d = diff(blend[k]);
        moved = moved + std::sqrt(dot3(d, d));
    }
    const float widen_each = moved * kGregoryWidenScale;
    Vec3 v[kGregoryNetVectors];
    float widen[kGregoryNetVectors];
    for (int k = 0; k < kGregoryNetVectors; ++k) {
        v[k] = diff(net[k]);
        widen[k] = widen_each;
    }
    return cone_of_vectors<kGregoryNetVectors>(v, widen);
}

/// The normal cone of a Gregory patch from its 20 Cartesian points: Sederberg & Meyers' cone of
/// its s- and t-tangent cones (gregory_direction_cone). With F+ = F- at every corner it is
/// tangent_cone_polynomial's cone of the equivalent Bezier patch.
PATCHCULL_CONES_INLINE NormalCone tangent_cone_gregory(const Vec3 g[kGregoryPoints]) {
    return combine_cones(gregory_direction_cone(g, kGregoryNetS, kGregoryBlendS),
                         gregory_direction_cone(g, kGregoryNetT, kGregoryBlendT));
}

/// Binomial weights folded into the tangent control vectors: U'_ab = C(2,a) C(3,b) U_ab,
/// V'_cd = C(3,c) C(2,d) V_cd.
inline constexpr float kC2[3] = {1, 2, 1};
inline constexpr float kC3[4] = {1, 3, 3, 1};

/// Control vectors of the normal patch N = B_u x B_v (bidegree 5) up to a positive factor per
/// vector: N(u,v) = sum_ij B5_i(u) B5_j(v) N_ij with N_ij = 9 / (C(5,i) C(5,j)) * out[6j + i],
///   out[6j + i] = sum_{a+c=i, b+d=j} U'_ab x V'_cd.
/// bound[6j + i] = sum over the same terms of |U'_ab|_1 |V'_cd|_1 (kNormalRoundoff * bound bounds
/// the rounding error of out[6j + i]).
PATCHCULL_CONES_INLINE void normal_patch_vectors(const BezierPatch& p, Vec3 out[36], float bound[36]) {
    Vec3 U[12], V[12];
    tangent_vectors(p, U, V);
    float lu[12], lv[12];
    for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 3; ++a) {
            Vec3& u = U[3 * b + a];
            const float w = kC2[a] * kC3[b];
            u = {u.x * w, u.y * w, u.z * w};
            lu[3 * b + a] = (std::fabs(u.x) + std::fabs(u.y)) + std::fabs(u.z);
        }
    for (int d = 0; d < 3; ++d)
        for (int c = 0; c < 4; ++c) {
            Vec3& v = V[4 * d + c];
            const float w = kC3[c] * kC2[d];
            v = {v.x * w, v.y * w, v.z * w};
            lv[4 * d + c] = (std::fabs(v.x) + std::fabs(v.y)) + std::fabs(v.z);
        }
    for (int j = 0; j < 6; ++j)
        for (int i = 0; i < 6; ++i) {
            float nx = 0, ny = 0, nz = 0, m = 0;
            const int a0 = i > 3 ? i - 3 : 0, a1 = i < 2 ? i : 2;
            const int b0 = j > 2 ? j - 2 : 0, b1 = j < 3 ? j : 3;
            for (int a = a0; a <= a1; ++a)
                for (int b = b0; b <= b1; ++b) {
                    const Vec3 u = U[3 * b + a], v = V[4 * (j - b) + (i - a)];
                    nx = std::fma(u.y, v.z, nx);
                    nx = std::fma(-u.z, v.y, nx);
                    ny = std::fma(u.z, v.x, ny);
                    ny = std::fma(-u.x, v.z, ny);
                    nz = std::fma(u.x, v.y, nz);
                    nz = std::fma(-u.y, v.x, nz);
                    m = std::fma(lu[3 * b + a], lv[4 * (j - b) + (i - a)], m);
                }
            out[6 * j + i] = {nx, ny, nz};
            bound[6 * j + i] = m;
        }
}

/// NCONE of a polynomial patch (no w check).
PATCHCULL_CONES_INLINE NormalCone normal_cone_polynomial(const BezierPatch& p) {
    Vec3 nv[36];
    float widen[36];
    normal_patch_vectors(p, nv, widen);
    for (int k = 0; k < 36; ++k) widen[k] = (2.0f * kNormalRoundoff) * widen[k];
    return cone_of_vectors<36>(nv, widen);
}

/// Centre of the box of n points point(0) .. point(n - 1); radius = max distance * kRadiusScale.
template <int n, class Point>
PATCHCULL_CONES_INLINE PatchSphere sphere_of(const Point& point) {
    Vec3 lo = point(0), hi = lo;
    for (int k = 1; k < n; ++k) {
        const Vec3 q = point(k);
        lo = {min_like_simd(lo.x, q.x), min_like_simd(lo.y, q.y), min_like_simd(lo.z, q.z)};
        hi = {max_like_simd(hi.x, q.x), max_like_simd(hi.y, q.y), max_like_simd(hi.z, q.z)};
    }
    const Vec3 c{(lo.x + hi.x) * 0.5f, (lo.y + hi.y) * 0.5f, (lo.z + hi.z) * 0.5f};
    float r2 = 0.0f;
    for (int k = 0; k < n; ++k) {
        const Vec3 q = point(k);
        const Vec3 d{q.x - c.x, q.y - c.y, q.z - c.z};
        r2 = max_like_simd(r2, dot3(d, d));
    }
    return {c, std::sqrt(r2) * kRadiusScale};
}

/// The sphere of a patch's (Cartesian) control points. kDivide: divide by w (rational patches);
/// false for polynomial patches (same values).
template <bool kDivide>
PATCHCULL_CONES_INLINE PatchSphere sphere_of_points(const BezierPatch& p) {
    return sphere_of<kPatchPoints>([&p](int k) {
        const Vec4 q = p.cp[k];
        if constexpr (kDivide) return Vec3{q.x / q.w, q.y / q.w, q.z / q.w};
        return Vec3{q.x, q.y, q.z};
    });
}

/// The sphere of a Gregory patch's 20 points (the surface lies in their convex hull).
PATCHCULL_CONES_INLINE PatchSphere sphere_of_gregory_points(const Vec3 g[kGregoryPoints]) {
    return sphere_of<kGregoryPoints>([g](int k) { return g[k]; });
}

/// The perspective back-facing test (derivation in cones.cpp): with d = e - c, L = |d|,
/// sb = r/L, cb = sqrt(1 - sb^2): culled iff valid, L > r, cos(alpha + beta) >= 0 and
/// a . d <= -L (sin(alpha + beta) + kFacingSlack).
PATCHCULL_CONES_INLINE bool back_facing(const NormalCone& cone, const PatchSphere& sphere, Vec3 eye) {
    const Vec3 d{eye.x - sphere.center.x, eye.y - sphere.center.y, eye.z - sphere.center.z};
    const float len = std::sqrt(dot3(d, d));
    const float sb = sphere.radius / len;
    const float cb = std::sqrt(std::fma(-sb, sb, 1.0f));
    const float sin_ab = std::fma(cone.sin_angle, cb, cone.cos_angle * sb);
    const float cos_ab = std::fma(cone.cos_angle, cb, -(cone.sin_angle * sb));
    const float ad = dot3(cone.axis, d);
    const float limit = len * (sin_ab + kFacingSlack);
    return cone.valid && len > sphere.radius && cos_ab >= 0.0f && ad <= -limit;
}

}  // namespace patchcull::cones_detail
