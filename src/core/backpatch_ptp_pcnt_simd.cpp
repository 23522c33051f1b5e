// The ptp back-patch kernel, SIMD, pcnt rule (patchcull/core/backpatch.h's PtpRule::pcnt): the body of
// backpatch_ptp_simd-inl.h compiled for every x86 target Highway attains, dispatched once at the first
// call. cull_ptp_simd (backpatch_ptp_simd.cpp) calls it; see that file for the arithmetic contract.

#include <cstddef>
#include <cstdint>

#include "core/ptp_internal.h"
#include "patchcull/core/patch.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/backpatch_ptp_pcnt_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/backpatch_ptp_simd-inl.h"

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {

void CullPtpPcnt(const PatchBatchView& patches, const ptp_detail::PtpClipRows& rows, std::uint8_t* culled) {
    ptp::CullGroups<true>(patches, rows, culled);
}

}  // namespace HWY_NAMESPACE
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace patchcull::ptp_detail {

HWY_EXPORT(CullPtpPcnt);

void cull_ptp_pcnt_simd(const PatchBatchView& patches, const PtpClipRows& rows, std::uint8_t* culled) {
    HWY_DYNAMIC_DISPATCH(CullPtpPcnt)(patches, rows, culled);
}

}  // namespace patchcull::ptp_detail
#endif  // HWY_ONCE
