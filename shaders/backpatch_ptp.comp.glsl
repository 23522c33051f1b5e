// ptp back-patch cull pass (BackpatchPtpPass, src/gl/backpatch_ptp_pass.cpp; Loop, Niessner &
// Eisenacher §3-6): the GPU twin of cull_ptp_scalar (include/patchcull/core/backpatch.h, src/core/backpatch_ptp.cpp)
// with Loop, Niessner & Eisenacher §6's parallel scheme:
// kPtpLanes = 16 invocations per patch, kPtpPatchesPerGroup = 8 patches per work group.
//
// Per patch (lane = gl_LocalInvocationID.x, the patch's slot in the group = .y):
// 1. lane k transforms control point k to clip space (rows x, y, w of s * object_to_clip, given
//    by the host exactly as ptp_clip_rows computes them) into shared memory;
// 2. the lanes share the schedule's 2x2 minors (kPtpPairCount pairs, round robin) in shared
//    memory;
// 3. lane tau = 4 (jv % 4) + (iu % 4) computes the 4 destinations {iu, iu + 4} x {jv, jv + 4} of
//    its 4x4 block (seed §6's load balance: 31 to 33 terms per lane), each summed in the CPU
//    schedule's order (ptp_schedule.h: table order within a destination, the same pair minors,
//    the corner formula for the 4 corner destinations), so every t is bit-identical to the CPU's
//    (pc_fma = std::fma; the other operations are single IEEE operations marked precise). A lane
//    owns its destinations alone: no write hazards, no atomics;
//    Each lane also computes the patch's rounding-error margin scales (ptp_schedule.h, "Rounding-
//    error margin": R, E, g1, g2 and the collapsed edges, from shared memory, in the CPU's order)
//    and the margins thr of its 4 destinations;
// 4. the 64 t and thr go to shared memory and are counted by a parallel reduction: lane i counts
//    how many of t[4i .. 4i+3] satisfy the rule (ncnt: t < -thr, pcnt: t <= -thr; NaN satisfies
//    neither), then a tree sum over the 16 lanes; culled when all 64 do (as the CPU).
// A link of the flag chain (flag_chain.h): patches culled earlier and displaced ones (margin > 0)
// take part in the barriers but are neither counted nor written; a culled patch gets
// kCullBackPatch. The 64 t and then the 64 thr go to kBindingPtpPlanes (128 floats per patch) on
// request (tests). With PC_PATCH_SOURCE the points come from the caller's patch source
// (patch_source.h). The host skips the dispatch (and clears the flags) when ptp_clip_rows would
// return false (alpha or det(object_to_clip) zero or not finite).
#version 450 core
#include "shared.h"
#include "pass_params.h"
#define PC_CONTROL_POINTS readonly
#define PC_CULL_FLAGS
#define PC_MAX_DISPLACEMENT readonly
#include "patch_buffers.h"
#include "exact_fma.h"
#include "ptp_schedule.h"
#include "ptp_tables.h"
#include "flag_chain.h"
#include "patch_source.h"

layout(local_size_x = kPtpLanes, local_size_y = kPtpPatchesPerGroup) in;

layout(std430, binding = kBindingPtpPlanes) writeonly buffer PtpPlanes {
    float ptp_planes[];  // 128 per patch (t[64], thr[64]), written only when u_write_planes
};

// Parameter names (pass_params.h's BackpatchPtpParams). u_zero is always 0.0 (the host sets it):
// the accumulators start from this run-time zero, not from a literal, because Mesa folds `x + 0.0`
// into x even in precise code, which turns the CPU's fma(w, v, +0) = +0 for v = -0 into -0
// (measured on llvmpipe: the sign of zero t differed).
#define u_rows ptp.rows
#define u_pcnt (ptp.pcnt != 0u)
#define u_write_planes (ptp.write_planes != 0u)
#define u_zero ptp.zero

shared vec4 s_object[kPtpPatchesPerGroup][16];
shared float s_x[kPtpPatchesPerGroup][16];
shared float s_y[kPtpPatchesPerGroup][16];
shared float s_w[kPtpPatchesPerGroup][16];
shared float s_mxy[kPtpPatchesPerGroup][kPtpPairCount];
shared float s_mxw[kPtpPatchesPerGroup][kPtpPairCount];
shared float s_myw[kPtpPatchesPerGroup][kPtpPairCount];
shared float s_t[kPtpPatchesPerGroup][64];
shared float s_thr[kPtpPatchesPerGroup][64];
shared uint s_count[kPtpPatchesPerGroup][kPtpLanes];

// a*b - c*d as fma(a, b, -(c*d)) (backpatch_ptp.cpp's minor2).
float pc_minor2(float a, float b, float c, float d) {
    precise float q = c * d;
    precise float r = pc_fma(a, b, -q);
    return r;
}

void sync_shared() {
    memoryBarrierShared();
    barrier();
}

void main() {
    const uint lane = gl_LocalInvocationID.x, slot = gl_LocalInvocationID.y;
    const uint index = gl_WorkGroupID.x * kPtpPatchesPerGroup + slot;
    const uint p = ptp.first_patch + index;
    // Inactive slots (past the range, culled earlier, displaced) still take part in every barrier.
#ifdef PC_PATCH_SOURCE
    // Every lane gathers the whole patch (a B-spline point's conversion needs its neighbours) and
    // takes point `lane`; a patch with an index past the points is inactive.
    bool in_range = index < ptp.patch_count && !pc_chain_culled(p) && pc_margin(p, ptp.has_margins) == 0.0;
    if (in_range) in_range = pc_gather_source(p);
#else
    const bool in_range = index < ptp.patch_count && !pc_chain_culled(p) && pc_margin(p, ptp.has_margins) == 0.0;
#endif

    // 1. Clip transform of control point `lane`: v = r.x X; v = fma(r.y, Y, v); ... (backpatch_ptp.cpp step 1).
    {
#ifdef PC_PATCH_SOURCE
        const vec4 P = in_range ? pc_source_points[lane] : vec4(0.0);
#else
        const vec4 P = in_range ? control_points[16u * p + lane] : vec4(0.0);
#endif
        precise float o[3];
        for (int r = 0; r < 3; ++r) {
            const vec4 row = u_rows[r];
            precise float v = row.x * P.x;
            v = pc_fma(row.y, P.y, v);
            v = pc_fma(row.z, P.z, v);
            o[r] = pc_fma(row.w, P.w, v);
        }
        s_object[slot][lane] = P;
        s_x[slot][lane] = o[0];
        s_y[slot][lane] = o[1];
        s_w[slot][lane] = o[2];
    }
    sync_shared();

    // 2. Minors of the schedule's pairs (a, b), as the minors of (a, b - a) (backpatch_ptp.cpp step 2).
    for (uint q = lane; q < kPtpPairCount; q += kPtpLanes) {
        const uint pair = kPtpPairs[q];
        const uint a = pair & 0xFFu, b = pair >> 8;
        const float ax = s_x[slot][a], ay = s_y[slot][a], aw = s_w[slot][a];
        precise float ex = s_x[slot][b] - ax;
        precise float ey = s_y[slot][b] - ay;
        precise float ew = s_w[slot][b] - aw;
        s_mxy[slot][q] = pc_minor2(ax, ey, ay, ex);
        s_mxw[slot][q] = pc_minor2(ax, ew, aw, ex);
        s_myw[slot][q] = pc_minor2(ay, ew, aw, ey);
    }
    sync_shared();

    // Margin scales of the patch (backpatch_ptp.cpp's rounding_margins), computed by every lane alike.
    bool finite;
    precise float g1, g2;
    uint collapsed = 0u;
    {
        precise vec4 mag = vec4(0.0);
        for (uint k = 0u; k < 16u; ++k) mag = max(mag, abs(s_object[slot][k]));
        precise float magnitude_sum = (mag.x + mag.y) + (mag.z + mag.w);
        finite = magnitude_sum <= uintBitsToFloat(0x7F7FFFFFu);  // FLT_MAX
        precise float row_bound[3];
        for (int r = 0; r < 3; ++r) {
            const vec4 row = abs(u_rows[r]);
            precise float v = row.x * mag.x;
            v = pc_fma(row.y, mag.y, v);
            v = pc_fma(row.z, mag.z, v);
            row_bound[r] = pc_fma(row.w, mag.w, v);
        }
        const float R = max(max(row_bound[0], row_bound[1]), row_bound[2]);
        vec3 lo = vec3(s_x[slot][0], s_y[slot][0], s_w[slot][0]), hi = lo;
        for (uint k = 1u; k < 16u; ++k) {
            const vec3 P = vec3(s_x[slot][k], s_y[slot][k], s_w[slot][k]);
            lo = min(lo, P);
            hi = max(hi, P);
        }
        precise vec3 extent = hi - lo;
        const float E = max(max(extent.x, extent.y), extent.z);
        precise float RR = R * R;
        precise float RRE = RR * E;
        precise float RRR = RR * R;
        precise float RE = R * E;
        precise float REE = RE * E;
        const float uf = uintBitsToFloat(kPtpMarginUnderflow);
        g1 = pc_fma(uf, RR, uf);
        g1 = pc_fma(uintBitsToFloat(kPtpMarginC3), RRR, g1);
        g1 = pc_fma(uintBitsToFloat(kPtpMarginC1), RRE, g1);
        g2 = uintBitsToFloat(kPtpMarginC2) * REE;
        for (uint e = 0u; e < 4u; ++e) {
            const vec4 a = s_object[slot][kPtpEdgePoints[4u * e]];
            bool same = true;
            for (uint i = 1u; i < 4u; ++i) same = same && all(equal(s_object[slot][kPtpEdgePoints[4u * e + i]], a));
            if (same) collapsed |= 1u << e;
        }
    }

    // 3. The 4 destinations of this lane's 4x4 block, each in the CPU schedule's order (step 3).
    const uint iu0 = lane & 3u, jv0 = lane >> 2;
    for (uint s = 0u; s < 4u; ++s) {
        const uint d = (iu0 + 4u * (s & 1u)) + 8u * (jv0 + 4u * (s >> 1));
        precise float acc = u_zero;
        const int ci = kPtpCornerOfDest[d];
        if (ci >= 0) {
            // t[d] = weight * det[p_a, p_b - p_a, p_c - p_a] (ptp_schedule.h's corners).
            const uint cr = kPtpCorners[ci];
            const uint a = (cr >> 8) & 0xFFu, b = (cr >> 16) & 0xFFu, c = cr >> 24;
            const float ax = s_x[slot][a], ay = s_y[slot][a], aw = s_w[slot][a];
            precise float d1x = s_x[slot][b] - ax;
            precise float d1y = s_y[slot][b] - ay;
            precise float d1w = s_w[slot][b] - aw;
            precise float d2x = s_x[slot][c] - ax;
            precise float d2y = s_y[slot][c] - ay;
            precise float d2w = s_w[slot][c] - aw;
            const float m_xy = pc_minor2(ax, d1y, ay, d1x);
            const float m_xw = pc_minor2(ax, d1w, aw, d1x);
            const float m_yw = pc_minor2(ay, d1w, aw, d1y);
            precise float v = d2x * m_yw;
            v = pc_fma(-d2y, m_xw, v);
            v = pc_fma(d2w, m_xy, v);
            acc = pc_fma(uintBitsToFloat(kPtpCornerWeights[ci]), v, acc);
        } else {
            const uint first = kPtpDestFirst[d], last = kPtpDestFirst[d + 1u];
            for (uint st = first; st < last; ++st) {
                const uint step = kPtpSteps[st];
                const uint q = step & 0xFFu, third = step >> 8;
                const float cx = s_x[slot][third], cy = s_y[slot][third], cw = s_w[slot][third];
                precise float v = cx * s_myw[slot][q];
                v = pc_fma(-cy, s_mxw[slot][q], v);
                v = pc_fma(cw, s_mxy[slot][q], v);
                acc = pc_fma(uintBitsToFloat(kPtpStepWeights[st]), v, acc);
            }
        }
        s_t[slot][d] = acc;
        // thr = fma(W_d (K_d + 12), g2, W_d g1), 0 where one of the destination's edges collapsed.
        precise float scaled = uintBitsToFloat(kPtpMarginWeights[d]) * g1;
        precise float thr = pc_fma(uintBitsToFloat(kPtpMarginWeightTerms[d]), g2, scaled);
        const uint iu = d & 7u, jv = d >> 3;
        const uint edges = (jv == 0u ? 1u : 0u) | (iu == 7u ? 2u : 0u) | (jv == 7u ? 4u : 0u) | (iu == 0u ? 8u : 0u);
        s_thr[slot][d] = (edges & collapsed) != 0u ? 0.0 : thr;
    }
    sync_shared();

    // 4. Sign count by parallel reduction (step 4): how many t satisfy the rule.
    uint ok = 0u;
    for (uint i = 0u; i < 4u; ++i) {
        const float t = s_t[slot][4u * lane + i], neg_thr = -s_thr[slot][4u * lane + i];
        const bool pass = finite && (u_pcnt ? (t <= neg_thr) : (t < neg_thr));  // NaN: false (kept)
        ok += pass ? 1u : 0u;
    }
    s_count[slot][lane] = ok;
    sync_shared();
    for (uint stride = kPtpLanes / 2u; stride > 0u; stride >>= 1) {
        if (lane < stride) s_count[slot][lane] += s_count[slot][lane + stride];
        sync_shared();
    }
    if (!in_range) return;
    if (lane == 0u && s_count[slot][0] == 64u) pc_chain_cull(p, kCullBackPatch);
    if (u_write_planes)
        for (uint i = 0u; i < 4u; ++i) {
            ptp_planes[128u * p + 4u * lane + i] = s_t[slot][4u * lane + i];
            ptp_planes[128u * p + 64u + 4u * lane + i] = s_thr[slot][4u * lane + i];
        }
}
