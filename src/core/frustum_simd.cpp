// View-frustum cull kernels, SIMD (patchcull/frustum.h), written once over Highway vectors and
// compiled for every x86 target Highway attains (SSSE3, SSE4, AVX2, AVX3 + the baseline); the best
// one the CPU supports is chosen once, at the first call (HWY_DYNAMIC_DISPATCH).
//
// Lanes are patches: lane j of a vector holds patch i+j, loaded straight from the SoA arrays
// (unaligned loads, so subranges at any offset work). The last partial group of a call is copied
// to a stack buffer whose unused lanes repeat the last patch, so no load ever leaves the caller's
// arrays (a subrange's padding may belong to other patches or lie past the allocation) and only
// valid decisions are written.
//
// Every operation mirrors the scalar reference in frustum.cpp, operation by operation (see the
// comment there): MulAdd <-> std::fma, Min/Max <-> `a < b ? a : b` / `a > b ? a : b`. Targets
// without an FMA instruction (HWY_NATIVE_FMA == 0: SSSE3, SSE4, emulated/scalar, i.e. pre-2013
// CPUs) would round MulAdd twice; there the kernel uses std::fma per lane instead, slow but exact.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

#include "patchcull/frustum.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/frustum_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using VF = hn::Vec<DF>;
using MF = hn::Mask<DF>;

constexpr std::size_t kMaxLanes = HWY_LANES(float);
constexpr int kComponents = 4 * kPatchPoints;  // 64 float arrays per batch

// a * b + c with a single rounding, like std::fma.
HWY_INLINE VF Fma(DF d, VF a, VF b, VF c) {
#if HWY_NATIVE_FMA
    (void)d;
    return hn::MulAdd(a, b, c);
#else
    HWY_ALIGN float fa[kMaxLanes], fb[kMaxLanes], fc[kMaxLanes];
    hn::Store(a, d, fa);
    hn::Store(b, d, fb);
    hn::Store(c, d, fc);
    for (std::size_t j = 0; j < hn::Lanes(d); ++j) fa[j] = std::fma(fa[j], fb[j], fc[j]);
    return hn::Load(d, fa);
#endif
}

// One group of Lanes(d) patches: component (k, c) of lane j is base[(4k + c) * stride + j].
struct Group {
    const float* base;
    std::size_t stride;
    HWY_INLINE VF load(DF d, int k, int c) const {
        return hn::LoadU(d, base + static_cast<std::size_t>(4 * k + c) * stride);
    }
};

// Writes 0/1 bytes for the first n lanes of culled.
HWY_INLINE void StoreDecisions(DF d, MF culled, std::uint8_t* out, std::size_t n) {
    const hn::RebindToSigned<DF> di;
    const hn::Rebind<std::uint8_t, DF> du8;
    const auto ones = hn::And(hn::BitCast(di, hn::VecFromMask(d, culled)), hn::Set(di, 1));
    const auto bytes = hn::DemoteTo(du8, ones);
    if (kMaxLanes == 1 || n == hn::Lanes(d)) {
        hn::StoreU(bytes, du8, out);
    } else {
        HWY_ALIGN std::uint8_t tmp[kMaxLanes];
        hn::Store(bytes, du8, tmp);
        std::memcpy(out, tmp, n);
    }
}

// frustum (see frustum.cpp for the operation order).
HWY_INLINE MF FrustumGroup(DF d, const Group& g, VF disp, const FrustumPlanes& planes) {
    VF rx[6], ry[6], rz[6], c[6], mx[6];
    for (int q = 0; q < 6; ++q) {
        rx[q] = hn::Set(d, planes.rows[q].x);
        ry[q] = hn::Set(d, planes.rows[q].y);
        rz[q] = hn::Set(d, planes.rows[q].z);
        c[q] = Fma(d, disp, hn::Set(d, planes.normal_length[q]), hn::Set(d, planes.rows[q].w));
        mx[q] = hn::Set(d, -std::numeric_limits<float>::infinity());
    }
    for (int k = 0; k < kPatchPoints; ++k) {
        const VF X = g.load(d, k, 0), Y = g.load(d, k, 1), Z = g.load(d, k, 2), W = g.load(d, k, 3);
        for (int q = 0; q < 6; ++q) {
            VF v = hn::Mul(rx[q], X);
            v = Fma(d, ry[q], Y, v);
            v = Fma(d, rz[q], Z, v);
            v = Fma(d, c[q], W, v);
            mx[q] = hn::Max(mx[q], v);
        }
    }
    const VF zero = hn::Zero(d);
    MF out = hn::Lt(mx[0], zero);
    for (int q = 1; q < 6; ++q) out = hn::Or(out, hn::Lt(mx[q], zero));
    return out;
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
    float m[4][4];  // m[r][c] = element (row r, column c)
};

// frustum-disp (see frustum.cpp for the operation order).
HWY_INLINE MF FrustumDispGroup(DF d, const Group& g, VF disp, const ClipMatrix& cm) {
    const VF one = hn::Set(d, 1.0f);
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
    auto plane_values = [&clip](int corner, VF v[6]) {
        const VF cx = clip[0][corner], cy = clip[1][corner], cz = clip[2][corner], cw = clip[3][corner];
        v[0] = hn::Add(cw, cx);
        v[1] = hn::Sub(cw, cx);
        v[2] = hn::Add(cw, cy);
        v[3] = hn::Sub(cw, cy);
        v[4] = cz;
        v[5] = hn::Sub(cw, cz);
    };
    VF mx[6], v[6];
    plane_values(0, mx);
    for (int corner = 1; corner < 8; ++corner) {
        plane_values(corner, v);
        for (int q = 0; q < 6; ++q) mx[q] = hn::Max(mx[q], v[q]);
    }
    const VF zero = hn::Zero(d);
    MF out = hn::Lt(mx[0], zero);
    for (int q = 1; q < 6; ++q) out = hn::Or(out, hn::Lt(mx[q], zero));
    return out;
}

// Runs group_fn over full groups in place and over the last partial group from a stack copy.
template <class GroupFn>
HWY_INLINE void ForEachGroup(const PatchBatchView& patches, const float* max_displacement,
                             std::uint8_t* culled, const GroupFn& group_fn) {
    const DF d;
    const std::size_t N = hn::Lanes(d);
    const std::size_t count = patches.count;
    std::size_t i = 0;
    for (; i + N <= count; i += N) {
        const Group g{patches.data + i, patches.stride};
        const VF disp = max_displacement ? hn::LoadU(d, max_displacement + i) : hn::Zero(d);
        StoreDecisions(d, group_fn(d, g, disp), culled + i, N);
    }
    if (i == count) return;
    // Tail: n < N patches, padded with copies of the last one (finite, positive weights).
    const std::size_t n = count - i;
    HWY_ALIGN float buf[kComponents * kMaxLanes];
    HWY_ALIGN float dbuf[kMaxLanes];
    for (int a = 0; a < kComponents; ++a) {
        const float* src = patches.data + static_cast<std::size_t>(a) * patches.stride + i;
        for (std::size_t j = 0; j < N; ++j) buf[a * N + j] = src[j < n ? j : n - 1];
    }
    for (std::size_t j = 0; j < N; ++j) dbuf[j] = max_displacement ? max_displacement[i + (j < n ? j : n - 1)] : 0.0f;
    const Group g{buf, N};
    StoreDecisions(d, group_fn(d, g, hn::Load(d, dbuf)), culled + i, n);
}

void CullFrustum(const PatchBatchView& patches, const float* max_displacement,
                 const FrustumPlanes& planes, std::uint8_t* culled) {
    ForEachGroup(patches, max_displacement, culled,
                 [&planes](DF d, const Group& g, VF disp) { return FrustumGroup(d, g, disp, planes); });
}

void CullFrustumDisp(const PatchBatchView& patches, const float* max_displacement,
                     const Mat4& object_to_clip, std::uint8_t* culled) {
    ClipMatrix cm;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) cm.m[r][c] = object_to_clip.at(r, c);
    ForEachGroup(patches, max_displacement, culled,
                 [&cm](DF d, const Group& g, VF disp) { return FrustumDispGroup(d, g, disp, cm); });
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

void cull_frustum_simd(const PatchBatchView& patches, const float* max_displacement,
                       const FrustumPlanes& planes, std::uint8_t* culled) {
    if (patches.count == 0) return;
    HWY_DYNAMIC_DISPATCH(CullFrustum)(patches, max_displacement, planes, culled);
}

void cull_frustum_disp_simd(const PatchBatchView& patches, const float* max_displacement,
                            const Mat4& object_to_clip, std::uint8_t* culled) {
    if (patches.count == 0) return;
    HWY_DYNAMIC_DISPATCH(CullFrustumDisp)(patches, max_displacement, object_to_clip, culled);
}

const char* simd_target_name() { return HWY_DYNAMIC_DISPATCH(TargetName)(); }

}  // namespace patchcull
#endif  // HWY_ONCE
