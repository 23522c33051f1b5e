// View-frustum cull kernels, SIMD (patchcull/core/frustum.h), written once over Highway vectors and
// compiled for every x86 target Highway attains (SSSE3, SSE4, AVX2, AVX3 + the baseline); the best
// one the CPU supports is chosen once, at the first call (HWY_DYNAMIC_DISPATCH).
//
// Lanes are patches, groups and partial-group padding as in simd_groups-inl.h.
//
// Every operation mirrors the scalar reference in frustum.cpp, operation by operation (see the
// comment there): Fma <-> std::fma (exact on every target, simd_groups-inl.h), Min/Max <->
// `a < b ? a : b` / `a > b ? a : b`.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

#include "core/patch_source_internal.h"
#include "patchcull/core/frustum.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/frustum_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/frustum_groups-inl.h"
#include "core/simd_groups-inl.h"

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using simd_groups::DF;
using simd_groups::Fma;
using simd_groups::ForEachGroup;
using simd_groups::Group;
using simd_groups::LoadPadded;
using simd_groups::MF;
using simd_groups::VF;

// frustum (see frustum_groups-inl.h for the operation order).
template <bool kMargins>
HWY_INLINE MF FrustumGroup(DF d, const Group& g, VF disp, const FrustumPlanes& planes) {
    const frustum_groups::ClipRows rows(d, planes);
    VF margin[6];
    if constexpr (kMargins) frustum_groups::Margins(d, disp, planes, margin);
    frustum_groups::PlaneMaxima maxima(d);
    for (int k = 0; k < kPatchPoints; ++k) {
        const VF X = g.load(d, k, 0), Y = g.load(d, k, 1), Z = g.load(d, k, 2), W = g.load(d, k, 3);
        VF c[4];
        frustum_groups::ClipPoint(d, rows, X, Y, Z, W, c);
        maxima.add<kMargins>(d, rows, c, W, margin);
    }
    return maxima.outside(d, rows);
}

// Cartesian AABB of the group's control points. kPolynomial: every weight is exactly 1, so
// X / W == X and the divisions are skipped (same values, bit for bit).
template <bool kPolynomial>
HWY_INLINE void CartesianBounds(DF d, const Group& g, VF lo[3], VF hi[3]) {
    auto cartesian = [&](int k, int a) {
        VF v = g.load(d, k, a);
        if constexpr (!kPolynomial) v = hn::Div(v, g.load(d, k, 3));
        return v;
    };
    for (int a = 0; a < 3; ++a) lo[a] = hi[a] = cartesian(0, a);
    for (int k = 1; k < kPatchPoints; ++k) {
        for (int a = 0; a < 3; ++a) {
            const VF v = cartesian(k, a);
            lo[a] = hn::Min(lo[a], v);
            hi[a] = hn::Max(hi[a], v);
        }
    }
}

struct ClipMatrix {
    float m[4][4];  // m[r][c] = element (row r, column c): FrustumPlanes::clip_rows
    float near_w, far_w, far_limit;
};

// frustum-disp (see frustum.cpp for the operation order).
HWY_INLINE MF FrustumDispGroup(DF d, const Group& g, VF disp, const ClipMatrix& cm) {
    const VF one = hn::Set(d, 1.0f);
    const VF zero = hn::Zero(d);
    VF probe = zero;  // non-finite probe over the raw coordinates (frustum.h)
    for (int k = 0; k < kPatchPoints; ++k)
        for (int a = 0; a < 4; ++a) probe = Fma(d, g.load(d, k, a), zero, probe);
    MF all_one = hn::Eq(g.load(d, 0, 3), one);
    for (int k = 1; k < kPatchPoints; ++k) all_one = hn::And(all_one, hn::Eq(g.load(d, k, 3), one));
    VF lo[3], hi[3];
    if (hn::AllTrue(d, all_one)) {
        CartesianBounds<true>(d, g, lo, hi);
    } else {
        CartesianBounds<false>(d, g, lo, hi);
    }
    VF box[3][2];
    for (int a = 0; a < 3; ++a) {
        box[a][0] = hn::Sub(lo[a], disp);
        box[a][1] = hn::Add(hi[a], disp);
    }
    VF clip[4][8];
    for (int r = 0; r < 4; ++r) {
        const VF m0 = hn::Set(d, cm.m[r][0]), m1 = hn::Set(d, cm.m[r][1]);
        const VF m2 = hn::Set(d, cm.m[r][2]), m3 = hn::Set(d, cm.m[r][3]);
        VF tz[2], tyz[4];
        for (int s = 0; s < 2; ++s) tz[s] = Fma(d, m2, box[2][s], m3);
        for (int j = 0; j < 2; ++j)
            for (int s = 0; s < 2; ++s) tyz[j * 2 + s] = Fma(d, m1, box[1][j], tz[s]);
        for (int i = 0; i < 2; ++i)
            for (int js = 0; js < 4; ++js) clip[r][i * 4 + js] = Fma(d, m0, box[0][i], tyz[js]);
    }
    const VF near_w = hn::Set(d, cm.near_w), far_w = hn::Set(d, cm.far_w);
    auto plane_values = [&](int corner, VF v[6]) {
        const VF cx = clip[0][corner], cy = clip[1][corner], cz = clip[2][corner], cw = clip[3][corner];
        v[0] = hn::Add(cw, cx);
        v[1] = hn::Sub(cw, cx);
        v[2] = hn::Add(cw, cy);
        v[3] = hn::Sub(cw, cy);
        v[4] = hn::Add(cz, hn::Mul(near_w, cw));
        v[5] = hn::Sub(hn::Mul(far_w, cw), cz);
    };
    VF mx[6], v[6];
    plane_values(0, mx);
    for (int corner = 1; corner < 8; ++corner) {
        plane_values(corner, v);
        for (int q = 0; q < 6; ++q) mx[q] = hn::Max(mx[q], v[q]);
    }
    MF out = hn::Lt(mx[5], hn::Set(d, cm.far_limit));
    for (int q = 0; q < 5; ++q) out = hn::Or(out, hn::Lt(mx[q], zero));
    return hn::And(out, hn::Eq(probe, zero));
}

// A group's per-patch displacement margins (zero without them).
HWY_INLINE VF GroupDisplacement(DF d, const float* max_displacement, std::size_t first, std::size_t valid) {
    return max_displacement ? LoadPadded(d, max_displacement + first, valid) : hn::Zero(d);
}

void CullFrustum(const PatchBatchView& patches, const float* max_displacement, const FrustumPlanes& planes,
                 std::uint8_t* culled) {
    if (max_displacement == nullptr) {
        ForEachGroup(patches, culled, [&](DF d, const Group& g, std::size_t, std::size_t) {
            return FrustumGroup<false>(d, g, hn::Zero(d), planes);
        });
        return;
    }
    ForEachGroup(patches, culled, [&](DF d, const Group& g, std::size_t first, std::size_t valid) {
        return FrustumGroup<true>(d, g, GroupDisplacement(d, max_displacement, first, valid), planes);
    });
}

void CullFrustumDisp(const PatchBatchView& patches, const float* max_displacement, const FrustumPlanes& planes,
                     std::uint8_t* culled) {
    ClipMatrix cm;
    for (int r = 0; r < 4; ++r) {
        const Vec4 row = planes.clip_rows[r];
        cm.m[r][0] = row.x;
        cm.m[r][1] = row.y;
        cm.m[r][2] = row.z;
        cm.m[r][3] = row.w;
    }
    cm.near_w = planes.near_w;
    cm.far_w = planes.far_w;
    cm.far_limit = planes.far_limit;
    ForEachGroup(patches, culled, [&](DF d, const Group& g, std::size_t first, std::size_t valid) {
        return FrustumDispGroup(d, g, GroupDisplacement(d, max_displacement, first, valid), cm);
    });
}

const char* TargetName() { return hwy::TargetName(HWY_TARGET); }

}  // namespace HWY_NAMESPACE
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace patchcull {

HWY_EXPORT(CullFrustum);
HWY_EXPORT(CullFrustumDisp);
HWY_EXPORT(TargetName);

void cull_frustum_simd(const PatchBatchView& patches, const float* max_displacement, const FrustumPlanes& planes,
                       std::uint8_t* culled) {
    if (patches.count == 0) return;
    HWY_DYNAMIC_DISPATCH(CullFrustum)(patches, max_displacement, planes, culled);
}

void cull_frustum_disp_simd(const PatchBatchView& patches, const float* max_displacement, const Mat4& object_to_clip,
                            ClipDepth depth, std::uint8_t* culled) {
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, depth);  // may throw: before the loop
    if (patches.count == 0) return;
    HWY_DYNAMIC_DISPATCH(CullFrustumDisp)(patches, max_displacement, planes, culled);
}

namespace detail {
void cull_frustum_disp_simd_planes(const PatchBatchView& patches, const float* max_displacement,
                                   const FrustumPlanes& planes, std::uint8_t* culled) {
    if (patches.count == 0) return;
    HWY_DYNAMIC_DISPATCH(CullFrustumDisp)(patches, max_displacement, planes, culled);
}
}  // namespace detail

const char* simd_target_name() { return HWY_DYNAMIC_DISPATCH(TargetName)(); }

}  // namespace patchcull
#endif  // HWY_ONCE
