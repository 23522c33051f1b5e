// Bounding-volume frustum tests, SIMD batch kernels (patchcull/objects/bounding_volumes.h), written once
// over Highway vectors and compiled for every x86 target Highway attains; the best one the CPU
// supports is chosen once, at the first call (HWY_DYNAMIC_DISPATCH), as in frustum_simd.cpp.
//
// Lanes are volumes. Spheres (4 floats) are loaded with LoadInterleaved4; AABBs (6 floats) as 2N
// interleaved points split into even (min) and odd (max) lanes (GatherIndex on the 1-lane scalar
// target); OBBs (15 floats) with GatherIndex at their stride. The last partial group is copied to a stack
// buffer whose unused lanes repeat the last volume, and only its valid results are written.
//
// Every operation mirrors the scalar reference in bounding_volumes.cpp operation by operation
// (the formulas are in the comment there): Fma <-> std::fma (exact on every target,
// simd_groups-inl.h), Max <-> `a > b ? a : b`, Abs <-> std::fabs, so the results are identical.

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "patchcull/objects/bounding_volumes.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "objects/bounding_volumes_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/simd_groups-inl.h"

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using simd_groups::DF;
using simd_groups::Fma;
using simd_groups::kMaxLanes;
using simd_groups::MF;
using simd_groups::VF;

static_assert(sizeof(Sphere) == 4 * sizeof(float), "Sphere is 4 packed floats");
static_assert(sizeof(Bounds) == 6 * sizeof(float), "Bounds is 6 packed floats");
static_assert(sizeof(Obb) == 15 * sizeof(float), "Obb is 15 packed floats");

// The per-plane constants of bounding_volumes.cpp (plane_const), broadcast.
struct PlaneVecs {
    VF x, y, z, w, len, nlen, pthr, nthr;
    bool x_pos, y_pos, z_pos;  // signs of the normal: which corner is the p-vertex
};

HWY_INLINE void MakePlanes(DF d, const FrustumPlanes& planes, PlaneVecs pv[6]) {
    for (int k = 0; k < 6; ++k) {
        const Vec4 r = planes.rows[k];
        const float pthr = std::fma(kVolumeRelativeEpsilon, std::fabs(r.w), 1e-30f);
        pv[k].x = hn::Set(d, r.x);
        pv[k].y = hn::Set(d, r.y);
        pv[k].z = hn::Set(d, r.z);
        pv[k].w = hn::Set(d, r.w);
        pv[k].len = hn::Set(d, planes.normal_length[k]);
        pv[k].nlen = hn::Set(d, -planes.normal_length[k]);
        pv[k].pthr = hn::Set(d, pthr);
        pv[k].nthr = hn::Set(d, -pthr);
        pv[k].x_pos = r.x >= 0;
        pv[k].y_pos = r.y >= 0;
        pv[k].z_pos = r.z >= 0;
    }
}

HWY_INLINE VF PlaneValue(DF d, const PlaneVecs& p, VF X, VF Y, VF Z) {
    return Fma(d, p.z, Z, Fma(d, p.y, Y, Fma(d, p.x, X, p.w)));
}

// Accumulates one plane's answer: outside |= outside_k, inside &= inside_k.
HWY_INLINE void Accumulate(DF d, const PlaneVecs& p, VF g, VF hi, VF lo, MF& outside, MF& inside) {
    outside = hn::Or(outside, hn::Lt(Fma(d, p.len, g, hi), p.nthr));
    inside = hn::And(inside, hn::Gt(Fma(d, p.nlen, g, lo), p.pthr));
}

HWY_INLINE void StoreContainment(DF /*d*/, MF outside, MF inside, Containment* out, std::size_t n) {
    const hn::RebindToSigned<DF> di;
    const hn::Rebind<std::uint8_t, DF> du8;
    auto v = hn::IfThenElse(hn::RebindMask(di, inside), hn::Set(di, 2), hn::Set(di, 1));
    v = hn::IfThenZeroElse(hn::RebindMask(di, outside), v);
    HWY_ALIGN std::uint8_t tmp[kMaxLanes];
    hn::Store(hn::DemoteTo(du8, v), du8, tmp);
    std::memcpy(out, tmp, n);
}

// group_fn(d, first volume of the group, outside, inside) for every group of Lanes(d) volumes; the
// last partial group from a padded copy.
template <class T, class GroupFn>
HWY_INLINE void ForEachVolumeGroup(const T* volumes, std::size_t n, Containment* out, const GroupFn& group_fn) {
    const DF d;
    const std::size_t N = hn::Lanes(d);
    std::size_t i = 0;
    MF outside, inside;
    for (; i + N <= n; i += N) {
        group_fn(d, volumes + i, outside, inside);
        StoreContainment(d, outside, inside, out + i, N);
    }
    if (i == n) return;
    const std::size_t valid = n - i;
    T buf[kMaxLanes];
    for (std::size_t j = 0; j < N; ++j) buf[j] = volumes[i + (j < valid ? j : valid - 1)];
    group_fn(d, buf, outside, inside);
    StoreContainment(d, outside, inside, out + i, valid);
}

// Lane j of the result is base[j * stride] (stride in floats).
template <int kStride>
HWY_INLINE VF GatherStrided(DF d, const float* base) {
    const hn::RebindToSigned<DF> di;
    HWY_ALIGN std::int32_t idx[kMaxLanes];
    for (std::size_t j = 0; j < hn::Lanes(d); ++j) idx[j] = static_cast<std::int32_t>(j * kStride);
    return hn::GatherIndex(d, base, hn::Load(di, idx));
}

void ClassifySpheres(const FrustumPlanes& planes, const Sphere* spheres, std::size_t n, Containment* out) {
    PlaneVecs pv[6];
    MakePlanes(DF(), planes, pv);
    ForEachVolumeGroup(spheres, n, out, [&](DF d, const Sphere* s, MF& outside, MF& inside) {
        VF cx, cy, cz, r;
        hn::LoadInterleaved4(d, &s->center.x, cx, cy, cz, r);
        const VF m = hn::Max(hn::Max(hn::Abs(cx), hn::Abs(cy)), hn::Abs(cz));
        const VF g = Fma(d, hn::Set(d, kVolumeRelativeEpsilon), hn::Add(hn::Add(m, m), r), r);
        outside = hn::Lt(r, hn::Zero(d));  // empty
        inside = hn::Not(outside);
        for (int k = 0; k < 6; ++k) {
            const VF v = PlaneValue(d, pv[k], cx, cy, cz);
            Accumulate(d, pv[k], g, v, v, outside, inside);
        }
        inside = hn::AndNot(outside, inside);
    });
}

void ClassifyAabbs(const FrustumPlanes& planes, const Bounds* boxes, std::size_t n, Containment* out) {
    PlaneVecs pv[6];
    MakePlanes(DF(), planes, pv);
    ForEachVolumeGroup(boxes, n, out, [&](DF d, const Bounds* b, MF& outside, MF& inside) {
        const float* base = &b->min.x;
#if HWY_TARGET == HWY_SCALAR
        const VF lx = GatherStrided<6>(d, base + 0), ly = GatherStrided<6>(d, base + 1);
        const VF lz = GatherStrided<6>(d, base + 2), hx = GatherStrided<6>(d, base + 3);
        const VF hy = GatherStrided<6>(d, base + 4), hz = GatherStrided<6>(d, base + 5);
#else
        // The boxes as 2N points (min, max, min, max, ...): two interleaved loads of N points,
        // then even lanes are the mins and odd lanes the maxes.
        const std::size_t N = hn::Lanes(d);
        VF x0, y0, z0, x1, y1, z1;
        hn::LoadInterleaved3(d, base, x0, y0, z0);
        hn::LoadInterleaved3(d, base + 3 * N, x1, y1, z1);
        const VF lx = hn::ConcatEven(d, x1, x0), hx = hn::ConcatOdd(d, x1, x0);
        const VF ly = hn::ConcatEven(d, y1, y0), hy = hn::ConcatOdd(d, y1, y0);
        const VF lz = hn::ConcatEven(d, z1, z0), hz = hn::ConcatOdd(d, z1, z0);
#endif
        VF m = hn::Abs(lx);
        m = hn::Max(m, hn::Abs(ly));
        m = hn::Max(m, hn::Abs(lz));
        m = hn::Max(m, hn::Abs(hx));
        m = hn::Max(m, hn::Abs(hy));
        m = hn::Max(m, hn::Abs(hz));
        const VF sum = hn::Add(hn::Add(hn::Add(hn::Add(hn::Add(lx, ly), lz), hx), hy), hz);
        const VF fin = hn::Mul(sum, hn::Zero(d));
        const VF g = hn::Add(hn::Mul(hn::Set(d, kVolumeRelativeEpsilon), hn::Add(m, m)), fin);
        outside = hn::Or(hn::Or(hn::Gt(lx, hx), hn::Gt(ly, hy)), hn::Gt(lz, hz));  // empty
        inside = hn::Not(outside);
        for (int k = 0; k < 6; ++k) {
            const PlaneVecs& p = pv[k];
            const VF hi = PlaneValue(d, p, p.x_pos ? hx : lx, p.y_pos ? hy : ly, p.z_pos ? hz : lz);
            const VF lo = PlaneValue(d, p, p.x_pos ? lx : hx, p.y_pos ? ly : hy, p.z_pos ? lz : hz);
            Accumulate(d, p, g, hi, lo, outside, inside);
        }
        inside = hn::AndNot(outside, inside);
    });
}

void ClassifyObbs(const FrustumPlanes& planes, const Obb* boxes, std::size_t n, Containment* out) {
    PlaneVecs pv[6];
    MakePlanes(DF(), planes, pv);
    ForEachVolumeGroup(boxes, n, out, [&](DF d, const Obb* b, MF& outside, MF& inside) {
        const float* base = &b->center.x;
        VF f[15];
        for (int c = 0; c < 15; ++c) f[c] = GatherStrided<15>(d, base + c);
        const VF cx = f[0], cy = f[1], cz = f[2];
        const VF h0 = f[12], h1 = f[13], h2 = f[14];
        const VF m = hn::Max(hn::Max(hn::Abs(cx), hn::Abs(cy)), hn::Abs(cz));
        const VF s = hn::Add(m, hn::Add(hn::Add(h0, h1), h2));
        const VF g = hn::Mul(hn::Set(d, kVolumeRelativeEpsilon), hn::Add(s, s));
        outside = hn::Lt(h0, hn::Zero(d));  // empty
        inside = hn::Not(outside);
        for (int k = 0; k < 6; ++k) {
            const PlaneVecs& p = pv[k];
            const VF v = PlaneValue(d, p, cx, cy, cz);
            VF dd[3];
            for (int i = 0; i < 3; ++i) {
                const VF ax = f[3 + 3 * i], ay = f[4 + 3 * i], az = f[5 + 3 * i];
                dd[i] = hn::Abs(Fma(d, p.z, az, Fma(d, p.y, ay, hn::Mul(p.x, ax))));
            }
            const VF e = Fma(d, h2, dd[2], Fma(d, h1, dd[1], hn::Mul(h0, dd[0])));
            Accumulate(d, p, g, hn::Add(v, e), hn::Sub(v, e), outside, inside);
        }
        inside = hn::AndNot(outside, inside);
    });
}

}  // namespace HWY_NAMESPACE
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace patchcull {

HWY_EXPORT(ClassifySpheres);
HWY_EXPORT(ClassifyAabbs);
HWY_EXPORT(ClassifyObbs);

void classify_spheres_simd(const FrustumPlanes& planes, const Sphere* spheres, std::size_t n, Containment* out) {
    if (n == 0) return;
    HWY_DYNAMIC_DISPATCH(ClassifySpheres)(planes, spheres, n, out);
}

void classify_aabbs_simd(const FrustumPlanes& planes, const Bounds* boxes, std::size_t n, Containment* out) {
    if (n == 0) return;
    HWY_DYNAMIC_DISPATCH(ClassifyAabbs)(planes, boxes, n, out);
}

void classify_obbs_simd(const FrustumPlanes& planes, const Obb* boxes, std::size_t n, Containment* out) {
    if (n == 0) return;
    HWY_DYNAMIC_DISPATCH(ClassifyObbs)(planes, boxes, n, out);
}

}  // namespace patchcull
#endif  // HWY_ONCE
