// Back-patch cull kernels tcone and ncone, SIMD (patchcull/core/backpatch.h), written once over
// Highway vectors and compiled for every x86 target Highway attains; the best one the CPU supports
// is chosen once, at the first call (HWY_DYNAMIC_DISPATCH), as in frustum_simd.cpp.
//
// Lanes are patches, groups and partial-group padding as in simd_groups-inl.h. Branch-free: every
// lane runs the whole cone construction; masks replace the scalar code's conditionals
// (x ? y : 0 -> IfThenElseZero, x ? y : z -> IfThenElse).
//
// Every operation mirrors the scalar reference in cones_internal.h, operation by operation:
// Fma <-> std::fma (exact on every target, simd_groups-inl.h), Min/Max <-> `a < b ? a : b` /
// `a > b ? a : b`, Sqrt and Div (correctly rounded) <-> std::sqrt and /, the same accumulation
// order; so the decisions are identical (tests/core/backpatch_cones_test.cpp checks every compiled
// target).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

#include "core/cones_internal.h"
#include "patchcull/core/backpatch.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/backpatch_cones_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/simd_groups-inl.h"

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace cones_simd {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
namespace cd = patchcull::cones_detail;

using patchcull::HWY_NAMESPACE::simd_groups::DF;
using patchcull::HWY_NAMESPACE::simd_groups::Fma;
using patchcull::HWY_NAMESPACE::simd_groups::ForEachGroup;
using patchcull::HWY_NAMESPACE::simd_groups::Group;
using patchcull::HWY_NAMESPACE::simd_groups::MF;
using patchcull::HWY_NAMESPACE::simd_groups::VF;

struct V3 {
    VF x, y, z;
};

// dot3 of cones_internal.h: mul, fma, fma.
HWY_INLINE VF Dot3(DF d, const V3& a, const V3& b) { return Fma(d, a.z, b.z, Fma(d, a.y, b.y, hn::Mul(a.x, b.x))); }

// cross3 of cones_internal.h.
HWY_INLINE V3 Cross3(DF d, const V3& a, const V3& b) {
    return {Fma(d, a.y, b.z, hn::Neg(hn::Mul(a.z, b.y))), Fma(d, a.z, b.x, hn::Neg(hn::Mul(a.x, b.z))),
            Fma(d, a.x, b.y, hn::Neg(hn::Mul(a.y, b.x)))};
}

HWY_INLINE V3 Scale(const V3& a, VF s) { return {hn::Mul(a.x, s), hn::Mul(a.y, s), hn::Mul(a.z, s)}; }

struct ConeV {
    V3 axis;
    VF cos_angle, sin_angle;
    MF valid;
};

// Control point k of every lane, and the difference of points k1 - k0.
HWY_INLINE V3 Point(DF d, const Group& g, int k) { return {g.load(d, k, 0), g.load(d, k, 1), g.load(d, k, 2)}; }
HWY_INLINE V3 Diff(DF d, const Group& g, int k1, int k0) {
    return {hn::Sub(g.load(d, k1, 0), g.load(d, k0, 0)), hn::Sub(g.load(d, k1, 1), g.load(d, k0, 1)),
            hn::Sub(g.load(d, k1, 2), g.load(d, k0, 2))};
}

// cd::is_polynomial.
HWY_INLINE MF Polynomial(DF d, const Group& g) {
    const VF one = hn::Set(d, 1.0f);
    MF all_one = hn::Eq(g.load(d, 0, 3), one);
    for (int k = 1; k < kPatchPoints; ++k) all_one = hn::And(all_one, hn::Eq(g.load(d, k, 3), one));
    return all_one;
}

// cd::cone_of_vectors.
template <int n>
HWY_INLINE ConeV ConeOfVectors(DF d, const V3* v, const VF* widen) {
    const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f);
    const VF min_len2 = hn::Set(d, cd::kMinLen2), max_len2 = hn::Set(d, cd::kMaxLen2);
    V3 h[n];
    VF ratio[n];
    MF used[n];
    const VF inf = hn::Set(d, std::numeric_limits<float>::infinity());
    const VF nan = hn::Set(d, std::numeric_limits<float>::quiet_NaN());
    MF bad = hn::Lt(one, zero);  // all false
    V3 lo{inf, inf, inf}, hi{hn::Neg(inf), hn::Neg(inf), hn::Neg(inf)};
    for (int k = 0; k < n; ++k) {
        const VF len2 = Dot3(d, v[k], v[k]);
        const MF nz = hn::And(hn::Ge(len2, min_len2), hn::Le(len2, max_len2));
        MF zero_ok = hn::Eq(len2, zero);
        if (widen) zero_ok = hn::And(zero_ok, hn::Eq(widen[k], zero));
        bad = hn::Or(bad, hn::Not(hn::Or(nz, zero_ok)));
        const VF inv = hn::IfThenElse(nz, hn::Div(one, hn::Sqrt(len2)), nan);
        h[k] = Scale(v[k], inv);
        if (widen) ratio[k] = hn::Mul(widen[k], inv);
        used[k] = nz;
        // NaN h (unused vector) first: Min/Max keep the second operand (see cones_internal.h).
        lo = {hn::Min(h[k].x, lo.x), hn::Min(h[k].y, lo.y), hn::Min(h[k].z, lo.z)};
        hi = {hn::Max(h[k].x, hi.x), hn::Max(h[k].y, hi.y), hn::Max(h[k].z, hi.z)};
    }
    const VF half = hn::Set(d, 0.5f);
    const V3 s{hn::Mul(hn::Add(lo.x, hi.x), half), hn::Mul(hn::Add(lo.y, hi.y), half),
               hn::Mul(hn::Add(lo.z, hi.z), half)};
    const VF slen2 = Dot3(d, s, s);
    const VF sinv = hn::IfThenElseZero(hn::Ge(slen2, min_len2), hn::Div(one, hn::Sqrt(slen2)));
    const V3 axis = Scale(s, sinv);
    VF cmin = one;
    for (int k = 0; k < n; ++k) {
        VF dk = Dot3(d, axis, h[k]);
        if (widen) dk = hn::Sub(dk, ratio[k]);
        cmin = hn::Min(cmin, hn::IfThenElse(used[k], dk, one));
    }
    const VF c = hn::Sub(cmin, hn::Set(d, cd::kCosSlack));
    ConeV cone;
    cone.axis = axis;
    cone.cos_angle = c;
    cone.sin_angle = hn::Sqrt(Fma(d, hn::Neg(c), c, one));
    cone.valid = hn::AndNot(bad, hn::And(hn::Ge(slen2, min_len2), hn::Gt(c, zero)));
    return cone;
}

// cd::tangent_vectors.
HWY_INLINE void TangentVectors(DF d, const Group& g, V3 U[12], V3 V[12]) {
    for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 3; ++a) U[3 * b + a] = Diff(d, g, 4 * b + a + 1, 4 * b + a);
    for (int dd = 0; dd < 3; ++dd)
        for (int c = 0; c < 4; ++c) V[4 * dd + c] = Diff(d, g, 4 * dd + 4 + c, 4 * dd + c);
}

// cd::combine_cones.
HWY_INLINE ConeV CombineCones(DF d, const ConeV& t, const ConeV& b) {
    const VF one = hn::Set(d, 1.0f);
    const V3 nrm = Cross3(d, t.axis, b.axis);
    const VF sin2 = Dot3(d, nrm, nrm);
    const VF ac = hn::Abs(Dot3(d, t.axis, b.axis));
    const VF st = t.sin_angle, sb = b.sin_angle;
    VF q = hn::Mul(st, st);
    q = Fma(d, hn::Mul(hn::Add(ac, ac), st), sb, q);
    q = Fma(d, sb, sb, q);
    const VF sn = hn::Add(hn::Sqrt(hn::Div(q, sin2)), hn::Set(d, cd::kSinSlack));
    const VF inv = hn::Div(one, hn::Sqrt(sin2));
    ConeV cone;
    cone.axis = Scale(nrm, inv);
    cone.sin_angle = sn;
    cone.cos_angle = hn::Sqrt(Fma(d, hn::Neg(sn), sn, one));
    cone.valid = hn::And(hn::And(t.valid, b.valid), hn::And(hn::Ge(sin2, hn::Set(d, cd::kMinLen2)), hn::Lt(sn, one)));
    return cone;
}

HWY_INLINE ConeV TangentCone(DF d, const Group& g) {
    V3 U[12], V[12];
    TangentVectors(d, g, U, V);
    const ConeV t = ConeOfVectors<12>(d, U, nullptr);
    const ConeV b = ConeOfVectors<12>(d, V, nullptr);
    return CombineCones(d, t, b);
}

// cd::normal_patch_vectors followed by cd::normal_cone_polynomial.
HWY_INLINE ConeV NormalPatchCone(DF d, const Group& g) {
    V3 U[12], V[12];
    TangentVectors(d, g, U, V);
    VF lu[12], lv[12];
    for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 3; ++a) {
            V3& u = U[3 * b + a];
            u = Scale(u, hn::Set(d, cd::kC2[a] * cd::kC3[b]));
            lu[3 * b + a] = hn::Add(hn::Add(hn::Abs(u.x), hn::Abs(u.y)), hn::Abs(u.z));
        }
    for (int dd = 0; dd < 3; ++dd)
        for (int c = 0; c < 4; ++c) {
            V3& v = V[4 * dd + c];
            v = Scale(v, hn::Set(d, cd::kC3[c] * cd::kC2[dd]));
            lv[4 * dd + c] = hn::Add(hn::Add(hn::Abs(v.x), hn::Abs(v.y)), hn::Abs(v.z));
        }
    V3 nv[36];
    VF widen[36];
    const VF two_k = hn::Set(d, 2.0f * cd::kNormalRoundoff);
    for (int j = 0; j < 6; ++j)
        for (int i = 0; i < 6; ++i) {
            VF nx = hn::Zero(d), ny = nx, nz = nx, m = nx;
            const int a0 = i > 3 ? i - 3 : 0, a1 = i < 2 ? i : 2;
            const int b0 = j > 2 ? j - 2 : 0, b1 = j < 3 ? j : 3;
            for (int a = a0; a <= a1; ++a)
                for (int b = b0; b <= b1; ++b) {
                    const V3& u = U[3 * b + a];
                    const V3& v = V[4 * (j - b) + (i - a)];
                    nx = Fma(d, u.y, v.z, nx);
                    nx = Fma(d, hn::Neg(u.z), v.y, nx);
                    ny = Fma(d, u.z, v.x, ny);
                    ny = Fma(d, hn::Neg(u.x), v.z, ny);
                    nz = Fma(d, u.x, v.y, nz);
                    nz = Fma(d, hn::Neg(u.y), v.x, nz);
                    m = Fma(d, lu[3 * b + a], lv[4 * (j - b) + (i - a)], m);
                }
            nv[6 * j + i] = {nx, ny, nz};
            widen[6 * j + i] = hn::Mul(two_k, m);
        }
    return ConeOfVectors<36>(d, nv, widen);
}

// cd::sphere_of_points<false> and cd::back_facing, and the polynomial test.
HWY_INLINE MF BackFacing(DF d, const Group& g, const ConeV& cone, const V3& eye) {
    V3 lo = Point(d, g, 0), hi = lo;
    for (int k = 1; k < kPatchPoints; ++k) {
        const V3 q = Point(d, g, k);
        lo = {hn::Min(lo.x, q.x), hn::Min(lo.y, q.y), hn::Min(lo.z, q.z)};
        hi = {hn::Max(hi.x, q.x), hn::Max(hi.y, q.y), hn::Max(hi.z, q.z)};
    }
    const VF half = hn::Set(d, 0.5f), zero = hn::Zero(d), one = hn::Set(d, 1.0f);
    const V3 c{hn::Mul(hn::Add(lo.x, hi.x), half), hn::Mul(hn::Add(lo.y, hi.y), half),
               hn::Mul(hn::Add(lo.z, hi.z), half)};
    VF r2 = zero;
    for (int k = 0; k < kPatchPoints; ++k) {
        const V3 q = Point(d, g, k);
        const V3 dq{hn::Sub(q.x, c.x), hn::Sub(q.y, c.y), hn::Sub(q.z, c.z)};
        r2 = hn::Max(r2, Dot3(d, dq, dq));
    }
    const VF r = hn::Mul(hn::Sqrt(r2), hn::Set(d, cd::kRadiusScale));

    const V3 dv{hn::Sub(eye.x, c.x), hn::Sub(eye.y, c.y), hn::Sub(eye.z, c.z)};
    const VF len = hn::Sqrt(Dot3(d, dv, dv));
    const VF sb = hn::Div(r, len);
    const VF cb = hn::Sqrt(Fma(d, hn::Neg(sb), sb, one));
    const VF sin_ab = Fma(d, cone.sin_angle, cb, hn::Mul(cone.cos_angle, sb));
    const VF cos_ab = Fma(d, cone.cos_angle, cb, hn::Neg(hn::Mul(cone.sin_angle, sb)));
    const VF ad = Dot3(d, cone.axis, dv);
    const VF limit = hn::Mul(len, hn::Add(sin_ab, hn::Set(d, cd::kFacingSlack)));
    MF out = hn::And(cone.valid, hn::Gt(len, r));
    out = hn::And(out, hn::Ge(cos_ab, zero));
    out = hn::And(out, hn::Le(ad, hn::Neg(limit)));
    return hn::And(out, Polynomial(d, g));
}

void CullTcone(const PatchBatchView& patches, Vec3 eye, std::uint8_t* culled) {
    // Compute-bound: software prefetching costs more than it saves (simd_groups-inl.h).
    ForEachGroup<false>(patches, culled, [&eye](DF d, const Group& g, std::size_t, std::size_t) {
        const V3 e{hn::Set(d, eye.x), hn::Set(d, eye.y), hn::Set(d, eye.z)};
        return BackFacing(d, g, TangentCone(d, g), e);
    });
}

void CullNcone(const PatchBatchView& patches, Vec3 eye, std::uint8_t* culled) {
    ForEachGroup<false>(patches, culled, [&eye](DF d, const Group& g, std::size_t, std::size_t) {
        const V3 e{hn::Set(d, eye.x), hn::Set(d, eye.y), hn::Set(d, eye.z)};
        return BackFacing(d, g, NormalPatchCone(d, g), e);
    });
}

}  // namespace HWY_NAMESPACE
}  // namespace cones_simd
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace patchcull {
namespace cones_simd {
HWY_EXPORT(CullTcone);
HWY_EXPORT(CullNcone);
}  // namespace cones_simd

void cull_tcone_simd(const PatchBatchView& patches, Vec3 eye, std::uint8_t* culled) {
    if (patches.count == 0) return;
    HWY_DYNAMIC_DISPATCH(cones_simd::CullTcone)(patches, eye, culled);
}

void cull_ncone_simd(const PatchBatchView& patches, Vec3 eye, std::uint8_t* culled) {
    if (patches.count == 0) return;
    HWY_DYNAMIC_DISPATCH(cones_simd::CullNcone)(patches, eye, culled);
}

}  // namespace patchcull
#endif  // HWY_ONCE
