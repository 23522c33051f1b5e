// Shared by the ptp kernels (backpatch_ptp.cpp, backpatch_ptp_simd.cpp, backpatch_ptp_pcnt_simd.cpp);
// private to patchcull.
#pragma once

#include <cstdint>

#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

namespace patchcull::ptp_detail {

/// Rows x, y, w of s * object_to_clip with s = sign(alpha) * sign(det object_to_clip) (backpatch_ptp.cpp
/// explains why), r[row][column].
struct PtpClipRows {
    float r[3][4];
};

/// False when nothing may be culled (alpha or det zero or not finite).
bool ptp_clip_rows(const Mat4& object_to_clip, float alpha, PtpClipRows& out);

/// The scalar kernel's 64 clip-space control plane z components (times the sign s) of one patch,
/// computed exactly as cull_ptp_scalar does (for tests: compared against double precision).
void ptp_control_planes_z(const BezierPatch& patch, const PtpClipRows& rows, float t[64]);

/// The scalar kernel's rounding-error margins thr[64] >= |t - exact t| of one patch (ptp_schedule.h,
/// "Rounding-error margin"); false (thr unspecified) when a coordinate is not finite (kept).
bool ptp_rounding_margins(const BezierPatch& patch, const PtpClipRows& rows, float thr[64]);

/// The SIMD kernel's pcnt rule (backpatch_ptp_pcnt_simd.cpp) on rows from ptp_clip_rows: culled[i]
/// as cull_ptp_simd with PtpRule::pcnt writes it.
void cull_ptp_pcnt_simd(const PatchBatchView& patches, const PtpClipRows& rows, std::uint8_t* culled);

}  // namespace patchcull::ptp_detail
