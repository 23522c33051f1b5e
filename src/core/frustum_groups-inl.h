// Per-target building blocks of the frustum test over Highway vectors, shared by the frustum
// kernel (frustum_simd.cpp) and the fused kernel (fused_cull_simd.cpp); private to patchcull.
//
// Lanes are patches (simd_groups-inl.h). Every operation mirrors frustum_plane_values /
// add_frustum_margins (include/patchcull/core/frustum.h) operation by operation: Fma <-> std::fma (exact
// on every target), Add/Sub/Mul <-> the rounded float operations, Max <-> `a > b ? a : b`. So the
// decisions equal cull_frustum_scalar's bit for bit (tests/core/frustum_test.cpp).
//
// A Highway "-inl.h" header (toggling include guard, included once per target after
// simd_groups-inl.h).
#if defined(PATCHCULL_CORE_FRUSTUM_GROUPS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATCHCULL_CORE_FRUSTUM_GROUPS_INL_H_
#undef PATCHCULL_CORE_FRUSTUM_GROUPS_INL_H_
#else
#define PATCHCULL_CORE_FRUSTUM_GROUPS_INL_H_
#endif

#include <limits>

#include <hwy/highway.h>

#include "core/simd_groups-inl.h"
#include "patchcull/core/frustum.h"

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {
namespace frustum_groups {
namespace hn = hwy::HWY_NAMESPACE;
using simd_groups::DF;
using simd_groups::Fma;
using simd_groups::Group;
using simd_groups::MF;
using simd_groups::VF;

// The clip matrix rows broadcast once per call, with the near and far plane coefficients.
struct ClipRows {
    VF m[4][4];  // m[r][c] = element (row r, column c)
    VF near_w, far_w, far_limit;
    HWY_INLINE ClipRows(DF d, const FrustumPlanes& planes)
        : near_w(hn::Set(d, planes.near_w)), far_w(hn::Set(d, planes.far_w)), far_limit(hn::Set(d, planes.far_limit)) {
        for (int r = 0; r < 4; ++r) {
            m[r][0] = hn::Set(d, planes.clip_rows[r].x);
            m[r][1] = hn::Set(d, planes.clip_rows[r].y);
            m[r][2] = hn::Set(d, planes.clip_rows[r].z);
            m[r][3] = hn::Set(d, planes.clip_rows[r].w);
        }
    }
};

// Clip coordinates c[0..3] = (x, y, z, w) of control point (X, Y, Z, W): hiz.h's step-2 order.
HWY_INLINE void ClipPoint(DF d, const ClipRows& rows, VF X, VF Y, VF Z, VF W, VF c[4]) {
    for (int r = 0; r < 4; ++r)
        c[r] = Fma(d, rows.m[r][3], W, Fma(d, rows.m[r][2], Z, Fma(d, rows.m[r][1], Y, hn::Mul(rows.m[r][0], X))));
}

// Running per-plane maxima of w + x, w - x, w + y, w - y, k + near_w w, far_w w - k, with the
// margins when given, and the non-finite probe (FrustumVerdict, frustum.h).
struct PlaneMaxima {
    VF mx[6];
    VF probe;
    HWY_INLINE explicit PlaneMaxima(DF d) : probe(hn::Zero(d)) {
        for (int q = 0; q < 6; ++q) mx[q] = hn::Set(d, -std::numeric_limits<float>::infinity());
    }
    template <bool kMargins>
    HWY_INLINE void add(DF d, const ClipRows& rows, const VF c[4], VF W, const VF margin[6]) {
        VF v[6] = {hn::Add(c[3], c[0]),
                   hn::Sub(c[3], c[0]),
                   hn::Add(c[3], c[1]),
                   hn::Sub(c[3], c[1]),
                   hn::Add(c[2], hn::Mul(rows.near_w, c[3])),
                   hn::Sub(hn::Mul(rows.far_w, c[3]), c[2])};
        for (int q = 0; q < 6; ++q) {
            if constexpr (kMargins) v[q] = Fma(d, margin[q], W, v[q]);
            mx[q] = hn::Max(mx[q], v[q]);
        }
        probe = Fma(d, v[4], hn::Zero(d), probe);
    }
    // Lanes outside some plane with every value finite: culled.
    HWY_INLINE MF outside(DF d, const ClipRows& rows) const {
        const VF zero = hn::Zero(d);
        MF out = hn::Lt(mx[5], rows.far_limit);
        for (int q = 0; q < 5; ++q) out = hn::Or(out, hn::Lt(mx[q], zero));
        return hn::And(out, hn::Eq(probe, zero));
    }
};

// margin[q] = fl(disp * normal_length[q]) per lane.
HWY_INLINE void Margins(DF d, VF disp, const FrustumPlanes& planes, VF margin[6]) {
    for (int q = 0; q < 6; ++q) margin[q] = hn::Mul(disp, hn::Set(d, planes.normal_length[q]));
}

}  // namespace frustum_groups
}  // namespace HWY_NAMESPACE
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#endif  // PATCHCULL_CORE_FRUSTUM_GROUPS_INL_H_
