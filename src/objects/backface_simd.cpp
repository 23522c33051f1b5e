// Back-face culling of triangles, SIMD (patchcull/objects/backface.h): the per-triangle test and the
// normal-mask lookup, written once over Highway vectors and compiled for every x86 target
// Highway attains; the best one the CPU supports is chosen once, at the first call
// (HWY_DYNAMIC_DISPATCH), as in frustum_simd.cpp.
//
// Per-triangle test: lanes are triangles. Their vertices are gathered from the indexed mesh
// (GatherIndex on the float array of the Vec3s; a group whose largest index would overflow the
// gather's signed 32-bit element offsets, and the last partial group, are copied lane by lane
// instead). The arithmetic mirrors backface.cpp operation by operation: Fma <-> std::fma
// (exact on every target, simd_groups-inl.h), Mul/Sub/Abs/Neg <-> the same scalar operations.
//
// Mask lookup: lanes are primitives; each gathers the 32-bit word of its class's bit (the
// BackMask's 64-bit words read as pairs of little-endian 32-bit words) and shifts the bit out.
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

#include "patchcull/objects/backface.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "objects/backface_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/simd_groups-inl.h"

static_assert(std::endian::native == std::endian::little, "the mask gather reads 64-bit words as 32-bit pairs");

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using simd_groups::DF;
using simd_groups::Fma;
using simd_groups::kMaxLanes;
using simd_groups::MF;
using simd_groups::StoreDecisions;
using simd_groups::VF;

// Largest vertex index whose float offset 3 * index + 2 fits the gather's int32.
constexpr std::uint32_t kMaxGatherIndex = (0x7fffffffu - 2u) / 3u;

HWY_INLINE MF TriangleGroup(DF d, const VF p[9], const VF eye[3]) {
    const VF e1x = hn::Sub(p[3], p[0]), e1y = hn::Sub(p[4], p[1]), e1z = hn::Sub(p[5], p[2]);
    const VF e2x = hn::Sub(p[6], p[0]), e2y = hn::Sub(p[7], p[1]), e2z = hn::Sub(p[8], p[2]);
    const VF wx = hn::Sub(eye[0], p[0]), wy = hn::Sub(eye[1], p[1]), wz = hn::Sub(eye[2], p[2]);
    const VF qx = hn::Mul(e1z, e2y), qy = hn::Mul(e1x, e2z), qz = hn::Mul(e1y, e2x);
    const VF nx = Fma(d, e1y, e2z, hn::Neg(qx));
    const VF ny = Fma(d, e1z, e2x, hn::Neg(qy));
    const VF nz = Fma(d, e1x, e2y, hn::Neg(qz));
    VF s = hn::Mul(nx, wx);
    s = Fma(d, ny, wy, s);
    s = Fma(d, nz, wz, s);
    const VF a1x = hn::Abs(e1x), a1y = hn::Abs(e1y), a1z = hn::Abs(e1z);
    const VF a2x = hn::Abs(e2x), a2y = hn::Abs(e2y), a2z = hn::Abs(e2z);
    const VF rx = hn::Mul(a1z, a2y), ry = hn::Mul(a1x, a2z), rz = hn::Mul(a1y, a2x);
    const VF px = Fma(d, a1y, a2z, rx);
    const VF py = Fma(d, a1z, a2x, ry);
    const VF pz = Fma(d, a1x, a2y, rz);
    VF perm = hn::Mul(px, hn::Abs(wx));
    perm = Fma(d, py, hn::Abs(wy), perm);
    perm = Fma(d, pz, hn::Abs(wz), perm);
    const VF margin =
        Fma(d, hn::Set(d, kTriangleTestErrorBound), perm, hn::Set(d, 32 * std::numeric_limits<float>::denorm_min()));
    auto same = [&](int a, int b) {
        return hn::And(hn::And(hn::Eq(p[3 * a], p[3 * b]), hn::Eq(p[3 * a + 1], p[3 * b + 1])),
                       hn::Eq(p[3 * a + 2], p[3 * b + 2]));
    };
    const MF degenerate = hn::Or(hn::Or(same(0, 1), same(0, 2)), same(1, 2));
    const MF back = hn::And(hn::Le(s, hn::Neg(margin)), hn::Le(margin, hn::Set(d, std::numeric_limits<float>::max())));
    return hn::Or(degenerate, back);
}

void CullTriangles(const Vec3* vertices, const std::uint32_t* indices, std::size_t count, Vec3 eye,
                   std::uint8_t* culled) {
    const DF d;
    const hn::RebindToUnsigned<DF> du;
    const hn::RebindToSigned<DF> di;
    const std::size_t N = hn::Lanes(d);
    const float* base = &vertices[0].x;
    static_assert(sizeof(Vec3) == 3 * sizeof(float), "Vec3 is three packed floats");
    const VF e[3] = {hn::Set(d, eye.x), hn::Set(d, eye.y), hn::Set(d, eye.z)};
    HWY_ALIGN float buf[9 * kMaxLanes];
    // Lane j of a group from triangle first + min(j, valid - 1), lane by lane.
    auto fill = [&](std::size_t first, std::size_t valid, VF p[9]) {
        for (std::size_t j = 0; j < N; ++j) {
            const std::size_t t = first + (j < valid ? j : valid - 1);
            for (int k = 0; k < 3; ++k) {
                const Vec3 v = vertices[indices[3 * t + k]];
                buf[(3 * k) * N + j] = v.x;
                buf[(3 * k + 1) * N + j] = v.y;
                buf[(3 * k + 2) * N + j] = v.z;
            }
        }
        for (int c = 0; c < 9; ++c) p[c] = hn::Load(d, buf + c * N);
    };
    std::size_t t = 0;
    for (; t + N <= count; t += N) {
        VF p[9];
        hn::Vec<decltype(du)> i0, i1, i2;
        hn::LoadInterleaved3(du, indices + 3 * t, i0, i1, i2);
        const auto largest = hn::Max(hn::Max(i0, i1), i2);
        // Signed compares (Highway 1.0 has no unsigned ones): an index >= 2^31 is negative here.
        const auto largest_i = hn::BitCast(di, largest);
        const auto fits = hn::And(hn::Gt(largest_i, hn::Set(di, -1)),
                                  hn::Lt(largest_i, hn::Set(di, static_cast<std::int32_t>(kMaxGatherIndex) + 1)));
        if (hn::AllTrue(di, fits)) {
            const hn::Vec<decltype(du)> idx[3] = {i0, i1, i2};
            for (int k = 0; k < 3; ++k) {
                const auto off = hn::Add(hn::ShiftLeft<1>(idx[k]), idx[k]);
                for (int c = 0; c < 3; ++c)
                    p[3 * k + c] =
                        hn::GatherIndex(d, base, hn::BitCast(di, hn::Add(off, hn::Set(du, std::uint32_t(c)))));
            }
        } else {
            fill(t, N, p);
        }
        StoreDecisions(d, TriangleGroup(d, p, e), culled + t, N);
    }
    if (t == count) return;
    VF p[9];
    fill(t, count - t, p);
    StoreDecisions(d, TriangleGroup(d, p, e), culled + t, count - t);
}

void CullByMask(const std::uint16_t* classes, std::size_t n, const std::uint64_t* bits, int class_count,
                std::uint8_t* culled) {
    const hn::ScalableTag<std::uint32_t> du;
    const hn::RebindToSigned<decltype(du)> di;
    const hn::Rebind<std::uint16_t, decltype(du)> d16;
    const hn::Rebind<std::uint8_t, decltype(du)> d8;
    const std::size_t N = hn::Lanes(du);
    const std::uint32_t* words = reinterpret_cast<const std::uint32_t*>(bits);
    const auto count = hn::Set(di, static_cast<std::int32_t>(class_count));
    const auto five_bits = hn::Set(du, 31u), one = hn::Set(du, 1u);
    auto group = [&](const std::uint16_t* src, std::uint8_t* out, std::size_t valid) {
        const auto cls = hn::PromoteTo(du, hn::LoadU(d16, src));
        const auto in_range = hn::RebindMask(du, hn::Lt(hn::BitCast(di, cls), count));  // cls < 2^16: signed is exact
        const auto word = hn::IfThenElseZero(in_range, hn::ShiftRight<5>(cls));
        const auto w = hn::GatherIndex(du, words, hn::BitCast(di, word));
        const auto bit = hn::IfThenElseZero(in_range, hn::And(w >> hn::And(cls, five_bits), one));
        const auto bytes = hn::DemoteTo(d8, hn::BitCast(di, bit));
        if (valid == N) {
            hn::StoreU(bytes, d8, out);
        } else {
            HWY_ALIGN std::uint8_t tmp[kMaxLanes];
            hn::Store(bytes, d8, tmp);
            std::memcpy(out, tmp, valid);
        }
    };
    std::size_t i = 0;
    for (; i + N <= n; i += N) group(classes + i, culled + i, N);
    if (i == n) return;
    HWY_ALIGN std::uint16_t tmp[kMaxLanes] = {};
    for (std::size_t j = 0; j < n - i; ++j) tmp[j] = classes[i + j];
    group(tmp, culled + i, n - i);
}

}  // namespace HWY_NAMESPACE
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace patchcull {

HWY_EXPORT(CullTriangles);
HWY_EXPORT(CullByMask);

void cull_backfacing_triangles_simd(const Vec3* vertices, const std::uint32_t* indices, std::size_t triangle_count,
                                    Vec3 eye, std::uint8_t* culled) {
    if (triangle_count == 0) return;
    HWY_DYNAMIC_DISPATCH(CullTriangles)(vertices, indices, triangle_count, eye, culled);
}

void cull_by_normal_mask_simd(const std::uint16_t* classes, std::size_t n, const BackMask& mask, std::uint8_t* culled) {
    if (n == 0) return;
    if (mask.class_count <= 0 || mask.bits.size() * 64 < static_cast<std::size_t>(mask.class_count)) {
        std::memset(culled, 0, n);
        return;
    }
    HWY_DYNAMIC_DISPATCH(CullByMask)(classes, n, mask.bits.data(), mask.class_count, culled);
}

}  // namespace patchcull
#endif  // HWY_ONCE
