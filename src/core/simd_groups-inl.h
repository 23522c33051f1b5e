// Per-target building blocks shared by the Highway SIMD kernels (frustum_simd.cpp,
// backpatch_cones_simd.cpp, backpatch_ptp_simd-inl.h, fused_cull_simd.cpp); private to patchcull.
//
// Lanes are patches: lane j of a vector holds patch i + j, loaded straight from a PatchBatchView's
// arrays (unaligned loads, so plain subranges at any offset work), in either layout (GroupAt): a
// plain view's 64 component arrays, or a blocked view's 16-patch block, where a group of
// Lanes(d) <= 16 patches never straddles two blocks. The last partial group of a call is copied
// (through PatchBatchView::at) to a stack buffer whose unused lanes repeat the last patch (finite
// values with the caller's weights), so no load ever leaves the caller's arrays (a subrange's
// padding may belong to other patches or lie past the allocation) and only valid decisions are
// written.
//
// Memory-bound kernels prefetch (ForEachGroup<true>): on a plain view each group reads 64 arrays a
// stride apart, more streams than the hardware prefetchers track; a blocked view is one stream,
// but the hardware prefetchers stop at every 4 KiB page, i.e. every block.
//
// Exact arithmetic: Fma, NegFma and FmaSub round once, like std::fma, on every target. Targets
// without an FMA instruction (HWY_NATIVE_FMA == 0: SSSE3, SSE4, emulated, i.e. pre-2013 CPUs)
// would round MulAdd twice; there they call std::fma per lane instead, slow but exact, so the
// kernels stay bit-identical to their scalar references.
//
// A Highway "-inl.h" header: included once per target by each kernel's foreach_target pass
// (after <hwy/highway.h>), hence the toggling include guard instead of #pragma once.
#if defined(PATCHCULL_CORE_SIMD_GROUPS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATCHCULL_CORE_SIMD_GROUPS_INL_H_
#undef PATCHCULL_CORE_SIMD_GROUPS_INL_H_
#else
#define PATCHCULL_CORE_SIMD_GROUPS_INL_H_
#endif

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include <hwy/cache_control.h>
#include <hwy/highway.h>

#include "patchcull/core/patch.h"

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {
namespace simd_groups {
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

// -a * b + c with a single rounding, like std::fma(-a, b, c).
HWY_INLINE VF NegFma(DF d, VF a, VF b, VF c) {
#if HWY_NATIVE_FMA
    (void)d;
    return hn::NegMulAdd(a, b, c);
#else
    return Fma(d, hn::Neg(a), b, c);
#endif
}

// a * b - c with a single rounding, like std::fma(a, b, -c).
HWY_INLINE VF FmaSub(DF d, VF a, VF b, VF c) {
#if HWY_NATIVE_FMA
    (void)d;
    return hn::MulSub(a, b, c);
#else
    return Fma(d, a, b, hn::Neg(c));
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

// The full group of patches starting at first (a multiple of Lanes(d), or any index for a plain
// view), read in place in either layout. Lanes(d) divides kBlockPatches on every x86 target, so a
// blocked group lies inside one block.
HWY_INLINE Group GroupAt(const PatchBatchView& patches, std::size_t first) {
    static_assert(kBlockPatches % kMaxLanes == 0, "a SIMD group must not straddle two blocks");
    if (patches.block_stride == 0) return Group{patches.data + first, patches.stride};
    return Group{patches.data + (first / kBlockPatches) * patches.block_stride + first % kBlockPatches, patches.stride};
}

// Prefetches (into L1) the 64 cache lines that patch `first` of a plain view lies on, one per
// component array; a 16-patch group reads one line per array when the arrays are 64-byte
// aligned. No-op past the view's end; prefetches never fault.
HWY_INLINE void PrefetchGroup(const PatchBatchView& patches, std::size_t first) {
    if (first >= patches.count) return;
    const float* p = patches.data + first;
    for (int a = 0; a < kComponents; ++a) hwy::Prefetch(p + static_cast<std::size_t>(a) * patches.stride);
}

// Prefetches the first kBlockPrefetchLines lines of the block of a blocked view that patch
// `first` lies in. A block is one 4 KiB run that the L2 streamer follows once it has seen a few
// misses in it, but it stops at every page boundary, i.e. at every block; touching the head of
// the block ahead restarts it early. 8 lines measured as fast at 1M patches as all 64 at an
// eighth of the instructions (docs/PERFORMANCE.md, "Batches at the memory roof").
constexpr int kBlockPrefetchLines = 8;
HWY_INLINE void PrefetchBlock(const PatchBatchView& patches, std::size_t first) {
    if (first >= patches.count) return;
    const float* b = patches.data + (first / kBlockPatches) * patches.block_stride;
    for (int l = 0; l < kBlockPrefetchLines; ++l) hwy::Prefetch(b + static_cast<std::size_t>(l) * kBlockPatches);
}

// The group of patches [first, first + valid) of patches, valid < Lanes(d), copied to buf
// (kComponents * kMaxLanes floats) with the unused lanes repeating the last patch.
HWY_INLINE Group CopyPartialGroup(DF d, const PatchBatchView& patches, std::size_t first, std::size_t valid,
                                  float* buf) {
    const std::size_t N = hn::Lanes(d);
    for (int a = 0; a < kComponents; ++a)
        for (std::size_t j = 0; j < N; ++j)
            buf[a * N + j] = patches.at(first + (j < valid ? j : valid - 1), a / 4, a % 4);
    return Group{buf, N};
}

// values[0 .. valid) as a vector, lanes past valid repeating the last value (a per-patch side
// input of a partial group, padded like CopyPartialGroup).
HWY_INLINE VF LoadPadded(DF d, const float* values, std::size_t valid) {
    if (valid == hn::Lanes(d)) return hn::LoadU(d, values);
    HWY_ALIGN float buf[kMaxLanes];
    for (std::size_t j = 0; j < hn::Lanes(d); ++j) buf[j] = values[j < valid ? j : valid - 1];
    return hn::Load(d, buf);
}

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

// culled[i] = group_fn(d, group, first, valid) for every group of patches: full groups in place
// (GroupAt), the last partial one from a padded stack copy. group_fn returns the culled mask of its
// lanes; first is the index of its lane 0 and valid the number of real patches in it (for side
// inputs, see LoadPadded).
//
// kPrefetch: software prefetching, once per 16 patches, plain_prefetch_distance() patches ahead
// on plain views (PrefetchGroup) and blocked_prefetch_distance() ahead on blocked views
// (PrefetchBlock). It pays for memory-bound kernels on batches beyond the caches (frustum: about
// 2x at 1M patches) and costs compute-bound ones 10-20% (tcone, ncone, ptp run near their
// instruction limit, below the memory roof, and pass false); docs/PERFORMANCE.md, "Batches at the
// memory roof".
template <bool kPrefetch = true, class GroupFn>
HWY_INLINE void ForEachGroup(const PatchBatchView& patches, std::uint8_t* culled, const GroupFn& group_fn) {
    const DF d;
    const std::size_t N = hn::Lanes(d);
    const std::size_t count = patches.count;
    std::size_t i = 0;
    if (patches.block_stride != 0) {
        const std::size_t ahead = kPrefetch ? blocked_prefetch_distance() : 0;
        for (; i + N <= count; i += N) {
            if (ahead != 0 && i % kBlockPatches == 0) PrefetchBlock(patches, i + ahead);
            StoreDecisions(d, group_fn(d, GroupAt(patches, i), i, N), culled + i, N);
        }
    } else {
        const std::size_t ahead = kPrefetch ? plain_prefetch_distance() : 0;
        for (; i + N <= count; i += N) {
            if (ahead != 0 && i % kBlockPatches == 0) PrefetchGroup(patches, i + ahead);
            StoreDecisions(d, group_fn(d, GroupAt(patches, i), i, N), culled + i, N);
        }
    }
    if (i == count) return;
    const std::size_t n = count - i;
    HWY_ALIGN float buf[kComponents * kMaxLanes];
    const Group g = CopyPartialGroup(d, patches, i, n, buf);
    StoreDecisions(d, group_fn(d, g, i, n), culled + i, n);
}

}  // namespace simd_groups
}  // namespace HWY_NAMESPACE
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#endif  // PATCHCULL_CORE_SIMD_GROUPS_INL_H_
