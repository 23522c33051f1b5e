// Occlusion test, SIMD (patchcull/hiz.h): steps 2-6 (clip transform, projectability, 48 divisions,
// window box, pixel rectangle) over Highway vectors, one patch per lane; step 1 is
// cull_frustum_simd (decisions identical to cull_frustum_scalar); steps 7-9 (level, <= 4 texel
// loads, compare) per patch with the scalar code of hiz.cpp: the level is data dependent and the
// loads are an irregular gather, which vectors do not speed up.
//
// Every operation mirrors patch_bounds() in hiz.cpp: Fma <-> std::fma (exact on every target,
// simd_groups-inl.h), Min/Max <-> `a < b ? a : b` /
// `a > b ? a : b`, Div <-> IEEE division, Floor <-> std::floor, ConvertTo of the clamped integral
// value <-> static_cast<int>. Lanes whose patch is not projectable (or frustum-culled) may hold
// garbage (divisions by w <= 0); they are never read.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "patchcull/frustum.h"
#include "patchcull/hiz.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/hiz_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/simd_groups-inl.h"

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using simd_groups::CopyPartialGroup;
using simd_groups::DF;
using simd_groups::Fma;
using simd_groups::Group;
using simd_groups::kComponents;
using simd_groups::kMaxLanes;
using simd_groups::MF;
using simd_groups::VF;
using DI = hn::RebindToSigned<DF>;
constexpr std::size_t kChunkHiZ = 256;  // patches per frustum pass; multiple of every lane count

struct Consts {
    float m[4][4];
    float abs_w[4];
    float half_w, half_h, wmax, hmax;
};

// Per-chunk bounds, one entry per patch.
struct ChunkBounds {
    HWY_ALIGN std::int32_t x0[kChunkHiZ], x1[kChunkHiZ], y0[kChunkHiZ], y1[kChunkHiZ];
    HWY_ALIGN float zmin[kChunkHiZ];
    HWY_ALIGN std::int32_t ok[kChunkHiZ];  // nonzero: projectable
};

// Steps 2-6 for a group of Lanes(d) patches; results to b at index at.
HWY_INLINE void BoundsGroup(DF d, const Group& g, const Consts& k_, ChunkBounds& b, std::size_t at) {
    const DI di;
    VF m[4][4], aw[4];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[r][c] = hn::Set(d, k_.m[r][c]);
    for (int c = 0; c < 4; ++c) aw[c] = hn::Set(d, k_.abs_w[c]);
    const VF safety = hn::Set(d, 0x1p-20f);
    MF ok = hn::FirstN(d, hn::Lanes(d));
    VF nxmin = hn::Zero(d), nxmax = nxmin, nymin = nxmin, nymax = nxmin, zmin = nxmin;
    for (int k = 0; k < kPatchPoints; ++k) {
        const VF X = g.load(d, k, 0), Y = g.load(d, k, 1), Z = g.load(d, k, 2), W = g.load(d, k, 3);
        VF c[4];
        for (int r = 0; r < 4; ++r) {
            VF t = hn::Mul(m[r][0], X);
            t = Fma(d, m[r][1], Y, t);
            t = Fma(d, m[r][2], Z, t);
            c[r] = Fma(d, m[r][3], W, t);
        }
        VF s = hn::Mul(aw[0], hn::Abs(X));
        s = Fma(d, aw[1], hn::Abs(Y), s);
        s = Fma(d, aw[2], hn::Abs(Z), s);
        s = Fma(d, aw[3], hn::Abs(W), s);
        ok = hn::And(ok, hn::Gt(c[3], hn::Mul(safety, s)));
        const VF nx = hn::Div(c[0], c[3]), ny = hn::Div(c[1], c[3]), nz = hn::Div(c[2], c[3]);
        if (k == 0) {
            nxmin = nxmax = nx;
            nymin = nymax = ny;
            zmin = nz;
        } else {
            nxmin = hn::Min(nxmin, nx);
            nxmax = hn::Max(nxmax, nx);
            nymin = hn::Min(nymin, ny);
            nymax = hn::Max(nymax, ny);
            zmin = hn::Min(zmin, nz);
        }
    }
    const VF hw = hn::Set(d, k_.half_w), hh = hn::Set(d, k_.half_h);
    const VF zero = hn::Zero(d), wmax = hn::Set(d, k_.wmax), hmax = hn::Set(d, k_.hmax);
    auto pixel = [&](VF v, VF half, VF vmax) {
        const VF win = Fma(d, v, half, half);
        return hn::ConvertTo(di, hn::Min(hn::Max(hn::Floor(win), zero), vmax));
    };
    hn::Store(pixel(nxmin, hw, wmax), di, b.x0 + at);
    hn::Store(pixel(nxmax, hw, wmax), di, b.x1 + at);
    hn::Store(pixel(nymin, hh, hmax), di, b.y0 + at);
    hn::Store(pixel(nymax, hh, hmax), di, b.y1 + at);
    hn::Store(zmin, d, b.zmin + at);
    hn::Store(hn::BitCast(di, hn::VecFromMask(d, ok)), di, b.ok + at);
}

void CullOcclusion(const PatchBatchView& patches, const Mat4& object_to_clip, const HiZPyramid& hiz,
                   std::uint8_t* decision) {
    const DF d;
    const std::size_t N = hn::Lanes(d);
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, ClipDepth::zero_to_one);  // converted below
    const int width = hiz.depth_width(), height = hiz.depth_height();
    Consts k_;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) k_.m[r][c] = object_to_clip.at(r, c);
    for (int c = 0; c < 4; ++c) k_.abs_w[c] = std::fabs(k_.m[3][c]);
    k_.half_w = 0.5f * static_cast<float>(width);
    k_.half_h = 0.5f * static_cast<float>(height);
    k_.wmax = static_cast<float>(width - 1);
    k_.hmax = static_cast<float>(height - 1);
    HWY_ALIGN float buf[kComponents * kMaxLanes];
    ChunkBounds b;
    for (std::size_t first = 0; first < patches.count; first += kChunkHiZ) {
        const std::size_t n = std::min(kChunkHiZ, patches.count - first);
        cull_frustum_simd(patches.subrange(first, n), nullptr, planes, decision + first);  // step 1
        std::size_t j = 0;
        for (; j + N <= n; j += N) BoundsGroup(d, Group{patches.data + first + j, patches.stride}, k_, b, j);
        if (j < n) BoundsGroup(d, CopyPartialGroup(d, patches, first + j, n - j, buf), k_, b, j);
        for (std::size_t i = 0; i < n; ++i) {  // steps 7-9, scalar
            if (decision[first + i] != kHiZVisible || b.ok[i] == 0) continue;
            const PixelRect rect{b.x0[i], b.y0[i], b.x1[i], b.y1[i]};
            if (hiz_rect_max(hiz, rect) < b.zmin[i]) decision[first + i] = kHiZOccluded;
        }
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace patchcull {

HWY_EXPORT(CullOcclusion);

void cull_occlusion_simd(const PatchBatchView& patches, const Mat4& object_to_clip, ClipDepth depth,
                         const HiZPyramid& hiz, std::uint8_t* decision) {
    if (patches.count == 0) return;
    HWY_DYNAMIC_DISPATCH(CullOcclusion)(patches, to_zero_to_one(object_to_clip, depth), hiz, decision);
}

}  // namespace patchcull
#endif  // HWY_ONCE
