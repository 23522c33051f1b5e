// The fused cull kernel, SIMD (patchcull/core/fused_cull.h), written once over Highway vectors and
// compiled for every x86 target Highway attains; the best one is chosen once, at the first call.
// Also cull_occlusion_simd (hiz.h), which is this kernel with the plan {frustum, occlusion}.
//
// Lanes are patches (simd_groups-inl.h: full groups read in place in either layout, the last
// partial group from a padded stack copy). Per group, the plan's stages run in order and the group
// leaves as soon as every valid lane is culled:
// - frustum: clip coordinates of the 16 control points (frustum_groups-inl.h, the frustum
//   kernel's operations), kept in a stack buffer for the occlusion stage, and the six plane maxima.
// - backpatch: the cone kernel (cull_tcone_simd / cull_ncone_simd) on the group itself, viewed as
//   a plain one-group batch (its data is in L1 after the first stage); identical decisions by
//   construction.
// - occlusion: hiz.h's steps 3-6 from the stored clip coordinates (the same operations as
//   cull_occlusion_scalar's patch_bounds: Fma <-> std::fma, Div <-> IEEE division, Floor, clamp,
//   ConvertTo of the integral value), steps 7-9 per lane with hiz.cpp's own functions; lanes
//   already culled are not looked up.
// The decision of a lane is the first stage that culls it, so it equals cull_fused_scalar's
// (tests/core/fused_cull_test.cpp, every plan, both layouts).
//
// The profiling variant (FusedProfile) runs every stage of the plan, no early exit, on a sample of
// the groups (the others run as usual), so that the cost model sees each stage's full verdicts
// (which subsets of stages would have decided each group) and its time: the time-stamp counter is
// read around each stage and converted to seconds at the call's own ticks per second.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "patchcull/core/fused_cull.h"

#if defined(__x86_64__) || defined(_M_X64)
#include <x86intrin.h>
#endif

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/fused_cull_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/frustum_groups-inl.h"
#include "core/simd_groups-inl.h"

#ifndef PATCHCULL_FUSED_TICKS_DEFINED
#define PATCHCULL_FUSED_TICKS_DEFINED
namespace patchcull::fused_detail {
// A cheap monotonic tick count for splitting a call's time between stages.
inline std::uint64_t ticks() {
#if defined(__x86_64__) || defined(_M_X64)
    return __rdtsc();
#else
    return static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
#endif
}
}  // namespace patchcull::fused_detail
#endif

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using simd_groups::CopyPartialGroup;
using simd_groups::DF;
using simd_groups::Fma;
using simd_groups::Group;
using simd_groups::GroupAt;
using simd_groups::kComponents;
using simd_groups::kMaxLanes;
using simd_groups::MF;
using simd_groups::VF;
using DI = hn::RebindToSigned<DF>;

// Broadcast constants of one call.
struct Consts {
    frustum_groups::ClipRows rows;
    VF abs_w[4];
    VF half_w, half_h, wmax, hmax, safety;
    Consts(DF d, const FusedCullSetup& setup, int width, int height) : rows(d, setup.planes) {
        const Vec4 w = setup.planes.clip_rows[3];
        abs_w[0] = hn::Set(d, std::fabs(w.x));
        abs_w[1] = hn::Set(d, std::fabs(w.y));
        abs_w[2] = hn::Set(d, std::fabs(w.z));
        abs_w[3] = hn::Set(d, std::fabs(w.w));
        half_w = hn::Set(d, 0.5f * static_cast<float>(width));
        half_h = hn::Set(d, 0.5f * static_cast<float>(height));
        wmax = hn::Set(d, static_cast<float>(width - 1));
        hmax = hn::Set(d, static_cast<float>(height - 1));
        safety = hn::Set(d, 0x1p-20f);  // hiz.h step 3
    }
};

// Per-group working memory (on the stack of the call).
struct Scratch {
    HWY_ALIGN float clip[kPatchPoints][4][kMaxLanes];
    HWY_ALIGN std::int32_t x0[kMaxLanes], x1[kMaxLanes], y0[kMaxLanes], y1[kMaxLanes], ok[kMaxLanes];
    HWY_ALIGN float zmin[kMaxLanes];
    HWY_ALIGN std::int32_t lanes[kMaxLanes];
    HWY_ALIGN std::uint8_t bytes[kMaxLanes];
};

// Lanes of mask m as bytes 0/1 in out[0 .. N).
HWY_INLINE void MaskToBytes(DF d, MF m, Scratch& s, std::uint8_t* out) {
    const DI di;
    hn::Store(hn::BitCast(di, hn::VecFromMask(d, m)), di, s.lanes);
    for (std::size_t j = 0; j < hn::Lanes(d); ++j) out[j] = s.lanes[j] != 0 ? 1 : 0;
}

// Stage frustum: clip coordinates stored, lanes outside a plane returned as bytes.
HWY_INLINE void FrustumStage(DF d, const Group& g, const Consts& k_, Scratch& s, std::uint8_t* culled) {
    frustum_groups::PlaneMaxima maxima(d);
    for (int k = 0; k < kPatchPoints; ++k) {
        const VF X = g.load(d, k, 0), Y = g.load(d, k, 1), Z = g.load(d, k, 2), W = g.load(d, k, 3);
        VF c[4];
        frustum_groups::ClipPoint(d, k_.rows, X, Y, Z, W, c);
        for (int r = 0; r < 4; ++r) hn::Store(c[r], d, s.clip[k][r]);
        maxima.add<false>(d, k_.rows, c, W, nullptr);
    }
    MaskToBytes(d, maxima.outside(d, k_.rows), s, culled);
}

// Stage backpatch: the cone kernel on the group itself (a plain view of its valid lanes).
HWY_INLINE void BackpatchStage(DF d, const Group& g, std::size_t valid, const FusedCullSetup& setup,
                               std::uint8_t* culled) {
    const PatchBatchView group{g.base, valid, g.stride};
    (setup.cone == BackPatchCone::tcone ? cull_tcone_simd : cull_ncone_simd)(group, setup.eye, culled);
    for (std::size_t j = valid; j < hn::Lanes(d); ++j) culled[j] = 0;
}

// Stage occlusion: hiz.h steps 3-6 from the stored clip coordinates, then 7-9 per lane that is
// still live (live[j] != 0) or, when all_lanes, for every lane.
HWY_INLINE void OcclusionStage(DF d, const Group& g, const Consts& k_, Scratch& s, const HiZPyramid& hiz,
                               const std::uint8_t* decided, bool all_lanes, std::size_t valid, std::uint8_t* culled) {
    const DI di;
    MF ok = hn::FirstN(d, hn::Lanes(d));
    VF nxmin = hn::Zero(d), nxmax = nxmin, nymin = nxmin, nymax = nxmin, zmin = nxmin;
    for (int k = 0; k < kPatchPoints; ++k) {
        const VF X = g.load(d, k, 0), Y = g.load(d, k, 1), Z = g.load(d, k, 2), W = g.load(d, k, 3);
        const VF cx = hn::Load(d, s.clip[k][0]), cy = hn::Load(d, s.clip[k][1]);
        const VF cz = hn::Load(d, s.clip[k][2]), cw = hn::Load(d, s.clip[k][3]);
        VF sum = hn::Mul(k_.abs_w[0], hn::Abs(X));
        sum = Fma(d, k_.abs_w[1], hn::Abs(Y), sum);
        sum = Fma(d, k_.abs_w[2], hn::Abs(Z), sum);
        sum = Fma(d, k_.abs_w[3], hn::Abs(W), sum);
        ok = hn::And(ok, hn::Gt(cw, hn::Mul(k_.safety, sum)));
        const VF nx = hn::Div(cx, cw), ny = hn::Div(cy, cw), nz = hn::Div(cz, cw);
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
    const VF zero = hn::Zero(d);
    auto pixel = [&](VF v, VF half, VF vmax) {
        const VF win = Fma(d, v, half, half);
        return hn::ConvertTo(di, hn::Min(hn::Max(hn::Floor(win), zero), vmax));
    };
    hn::Store(pixel(nxmin, k_.half_w, k_.wmax), di, s.x0);
    hn::Store(pixel(nxmax, k_.half_w, k_.wmax), di, s.x1);
    hn::Store(pixel(nymin, k_.half_h, k_.hmax), di, s.y0);
    hn::Store(pixel(nymax, k_.half_h, k_.hmax), di, s.y1);
    hn::Store(zmin, d, s.zmin);
    hn::Store(hn::BitCast(di, hn::VecFromMask(d, ok)), di, s.ok);
    for (std::size_t j = 0; j < hn::Lanes(d); ++j) {
        culled[j] = 0;
        if (j >= valid || s.ok[j] == 0 || (!all_lanes && decided[j] != kFusedVisible)) continue;
        const PixelRect rect{s.x0[j], s.y0[j], s.x1[j], s.y1[j]};
        if (hiz_rect_max(hiz, rect) < s.zmin[j]) culled[j] = 1;
    }
}

constexpr std::uint8_t kDecisionOf[kFusedStages] = {kFusedFrustumCulled, kFusedBackPatchCulled, kFusedOccluded};

// One group through the plan. decision[0 .. valid) receives its decisions.
template <bool kProfile>
HWY_INLINE void FusedGroup(DF d, const Group& g, std::size_t valid, const FusedCullSetup& setup, const FusedPlan& plan,
                           const Consts& k_, Scratch& s, std::uint8_t* decision, FusedCullStats* stats,
                           FusedProfile* profile) {
    HWY_ALIGN std::uint8_t dec[kMaxLanes] = {};
    HWY_ALIGN std::uint8_t stage_culled[kFusedStages][kMaxLanes] = {};
    std::size_t live = valid;
    for (int pos = 0; pos < plan.count; ++pos) {
        if (!kProfile && live == 0) break;
        const FusedStage stage = plan.stages[pos];
        const int si = static_cast<int>(stage);
        std::uint8_t* culled = stage_culled[si];
        std::uint64_t t0 = 0;
        if constexpr (kProfile) t0 = fused_detail::ticks();
        switch (stage) {
            case FusedStage::frustum:
                FrustumStage(d, g, k_, s, culled);
                break;
            case FusedStage::backpatch:
                BackpatchStage(d, g, valid, setup, culled);
                break;
            case FusedStage::occlusion:
                OcclusionStage(d, g, k_, s, *setup.hiz, dec, kProfile, valid, culled);
                break;
        }
        if constexpr (kProfile) profile->ticks[si] += fused_detail::ticks() - t0;
        if (stats) ++stats->groups_entered[pos];
        std::uint64_t newly = 0;
        for (std::size_t j = 0; j < valid; ++j) {
            if (dec[j] == kFusedVisible && culled[j]) {
                dec[j] = kDecisionOf[si];
                ++newly;
            }
        }
        live -= newly;
        if (stats) stats->patches_culled[si] += newly;
    }
    std::memcpy(decision, dec, valid);
    if (stats) ++stats->groups;
    if constexpr (kProfile) {
        ++profile->groups;
        unsigned in_plan = 0;
        for (int pos = 0; pos < plan.count; ++pos) in_plan |= 1u << static_cast<unsigned>(plan.stages[pos]);
        for (unsigned subset = 1; subset < (1u << kFusedStages); ++subset) {
            if ((subset & ~in_plan) != 0) continue;
            std::uint64_t culled = 0;
            for (std::size_t j = 0; j < valid; ++j) {
                bool any = false;
                for (int si = 0; si < kFusedStages; ++si) any = any || ((subset >> si) & 1u && stage_culled[si][j]);
                culled += any ? 1 : 0;
            }
            profile->patches_culled_by[subset] += culled;
            if (culled == valid) ++profile->decided[subset];
        }
    }
}

// sample: with kProfile, every sample-th group is profiled, the others run ordinarily.
template <bool kProfile>
void CullFusedImpl(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
                   std::uint8_t* decision, FusedCullStats* stats, FusedProfile* profile, std::size_t sample) {
    const DF d;
    const std::size_t N = hn::Lanes(d);
    const int width = setup.hiz ? setup.hiz->depth_width() : 1, height = setup.hiz ? setup.hiz->depth_height() : 1;
    const Consts k_(d, setup, width, height);
    Scratch s;
    auto group = [&](const Group& g, std::size_t first, std::size_t valid) {
        if (kProfile && (first / N) % sample == 0) {
            FusedGroup<true>(d, g, valid, setup, plan, k_, s, decision + first, nullptr, profile);
        } else {
            FusedGroup<false>(d, g, valid, setup, plan, k_, s, decision + first, stats, nullptr);
        }
    };
    std::size_t i = 0;
    for (; i + N <= patches.count; i += N) group(GroupAt(patches, i), i, N);
    if (i < patches.count) {
        HWY_ALIGN float buf[kComponents * kMaxLanes];
        const std::size_t valid = patches.count - i;
        group(CopyPartialGroup(d, patches, i, valid, buf), i, valid);
    }
}

void CullFused(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
               std::uint8_t* decision, FusedCullStats* stats) {
    CullFusedImpl<false>(patches, setup, plan, decision, stats, nullptr, 1);
}

void CullFusedProfile(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
                      std::uint8_t* decision, FusedProfile* profile, std::size_t max_profiled_groups) {
    const std::size_t groups = (patches.count + hn::Lanes(DF()) - 1) / hn::Lanes(DF());
    const std::size_t sample = max_profiled_groups == 0 ? 1 : std::max<std::size_t>(1, groups / max_profiled_groups);
    CullFusedImpl<true>(patches, setup, plan, decision, nullptr, profile, sample);
}

}  // namespace HWY_NAMESPACE
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace patchcull {

HWY_EXPORT(CullFused);
HWY_EXPORT(CullFusedProfile);

void cull_fused_simd(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
                     std::uint8_t* decision, FusedCullStats* stats) {
    if (patches.count == 0) return;
    HWY_DYNAMIC_DISPATCH(CullFused)(patches, setup, plan, decision, stats);
}

void cull_fused_profile_simd(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
                             std::uint8_t* decision, FusedProfile& profile, std::size_t max_profiled_groups) {
    if (patches.count == 0) return;
    const auto start = std::chrono::steady_clock::now();
    const std::uint64_t t0 = fused_detail::ticks();
    HWY_DYNAMIC_DISPATCH(CullFusedProfile)(patches, setup, plan, decision, &profile, max_profiled_groups);
    profile.call_ticks += fused_detail::ticks() - t0;
    profile.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void cull_occlusion_simd(const PatchBatchView& patches, const Mat4& object_to_clip, ClipDepth depth,
                         const HiZPyramid& hiz, std::uint8_t* decision) {
    check_hiz_convention(hiz, depth, "cull_occlusion_simd");
    FusedCullSetup setup;
    setup.planes = make_frustum_planes(object_to_clip, depth);
    setup.hiz = &hiz;
    FusedPlan plan;
    plan.stages[0] = FusedStage::frustum;
    plan.stages[1] = FusedStage::occlusion;
    plan.count = 2;
    cull_fused_simd(patches, setup, plan, decision, nullptr);
}

}  // namespace patchcull
#endif  // HWY_ONCE
