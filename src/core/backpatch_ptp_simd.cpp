// Parametric tangent plane (ptp) back-patch cull kernel, SIMD (patchcull/core/backpatch.h), written
// once over Highway vectors and compiled for every x86 target Highway attains; the best one the
// CPU supports is chosen once, at the first call (HWY_DYNAMIC_DISPATCH). Same structure as
// frustum_simd.cpp.
//
// Lanes are patches, groups and partial-group padding as in simd_groups-inl.h.
//
// The operations and their order are the scalar reference's (backpatch_ptp.cpp), fully unrolled at compile
// time over the schedule of ptp_schedule.h (pair indices, third points, weights and destination
// groups are constants, so the stack arrays of points and minors are addressed with constant
// offsets): MulAdd <-> std::fma, NegMulAdd(a, b, c) <-> std::fma(-a, b, c), MulSub(a, b, c) <->
// std::fma(a, b, -c) (exact on every target, simd_groups-inl.h), every other product and sum
// separately rounded, and no Mul feeding a plain Add/Sub (GCC would contract that into an fma on
// FMA targets only; see backpatch_ptp.cpp).
//
// The kernel body is backpatch_ptp_simd-inl.h; this file compiles it for the ncnt rule and holds
// the entry, backpatch_ptp_pcnt_simd.cpp for the pcnt rule (two translation units, so a parallel
// build compiles the two unrolled rules at once).

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "core/ptp_internal.h"
#include "patchcull/core/backpatch.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/backpatch_ptp_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/backpatch_ptp_simd-inl.h"

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {

void CullPtpNcnt(const PatchBatchView& patches, const ptp_detail::PtpClipRows& rows, std::uint8_t* culled) {
    ptp::CullGroups<false>(patches, rows, culled);
}

}  // namespace HWY_NAMESPACE
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace patchcull {

HWY_EXPORT(CullPtpNcnt);

void cull_ptp_simd(const PatchBatchView& patches, const Mat4& object_to_clip, float alpha, PtpRule rule,
                   std::uint8_t* culled) {
    if (patches.count == 0) return;
    ptp_detail::PtpClipRows rows;
    if (!ptp_detail::ptp_clip_rows(object_to_clip, alpha, rows)) {
        std::memset(culled, 0, patches.count);
        return;
    }
    if (rule == PtpRule::pcnt) {
        ptp_detail::cull_ptp_pcnt_simd(patches, rows, culled);
    } else {
        HWY_DYNAMIC_DISPATCH(CullPtpNcnt)(patches, rows, culled);
    }
}

}  // namespace patchcull
#endif  // HWY_ONCE
