// Parametric tangent plane (ptp) back-patch cull kernel, scalar reference (patchcull/core/backpatch.h,
// Loop, Niessner & Eisenacher §3-6). The SIMD kernel (backpatch_ptp_simd.cpp) does the same operations in
// the same order; the schedule both follow, and the FLOP count before/after sharing minors, is in
// ptp_schedule.h.
//
// Per patch:
// 1. The 16 control points go to clip space, x, y and w only (cross4Z never needs z):
//    X = fma(r.w, P.w, fma(r.z, P.z, fma(r.y, P.y, r.x * P.x))) per row r.
// 2. 2x2 minors of the schedule's pairs (a, b), computed as the minors of (a, b - a) (the same
//    values, exactly 0 when b == a), each as fma(a1, e2, -(a2 * e1)).
// 3. For each destination d in 0..63: acc = 0; for each of its terms (table order)
//      c = p.x * m_yw;  c = fma(-p.y, m_xw, c);  c = fma(p.w, m_xy, c);  acc = fma(weight, c, acc)
//    (corner destinations: the same with the anchor's difference vectors, ptp_schedule.h).
// 4. ncnt: culled when every acc < -thr; pcnt: culled when every acc <= -thr, thr >= 0 the
//    per-destination bound on acc's rounding error (ptp_schedule.h, "Rounding-error margin"; 0 on
//    a collapsed edge, whose planes are exact zeros, so Pcnt still culls degenerate patches). A
//    NaN anywhere fails the comparisons, so the patch is kept.
//
// Orientation. With object-space control points b and clip points M b, cross4 transforms as
// cross4(Ma, Mb, Mc) = det(M) M^-T cross4(a, b, c), so for the clip-space eye f = M e = (0,0,alpha,0)
//   alpha * t_clip.z = f . t_clip = det(M) * (e . t_object).
// backpatch.h's literal rule "culled when all alpha * t_z < 0" is the object-space rule e . T < 0
// only when det(M) > 0. A GL perspective() [[sx,0,0,0],[0,sy,0,0],[0,0,A,alpha],[0,0,-1,0]] has
// det = sx * sy * alpha < 0 (it flips handedness), so with a rigid view matrix the literal rule
// would cull exactly the front-facing patches; a mirroring model matrix flips det(M) once more.
// The kernels therefore evaluate s = sign(alpha) * sign(det M) once per call and use the rows of
// s * M: cross4Z is cubic in the points, so every t comes out multiplied by s^3 = s, exactly
// (negation is exact). Then "every t < 0" is exactly "every e . t_i < 0" for the object-space eye
// e = M^-1 (0, 0, alpha, 0), the contract's meaning (for projection * view this is +1: the rule is
// "all t_z < 0"). alpha == 0, det M == 0 or either not finite: nothing is culled.
// Bit-exact scalar/SIMD agreement: std::fma where SIMD uses MulAdd / NegMulAdd / MulSub, every
// other operation separately rounded, and no expression GCC could contract on its own: GCC's
// default for C++ is -ffp-contract=fast even with -std=c++20 (it does turn a*b - c*d into an fma,
// scalar and intrinsics alike, checked with g++ 12), so every product here feeds an explicit fma
// or is a lone multiply whose only use is an fma operand, which GCC never fuses.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/ptp_internal.h"
#include "core/ptp_schedule.h"
#include "patchcull/core/backpatch.h"

// As in frustum.cpp: a clone with FMA enabled so std::fma is one instruction (identical results).
#include "core/scalar_clones.h"

namespace patchcull {

int ptp_orientation_sign(const Mat4& object_to_clip, float alpha) {
    // det in double: the entries are floats, so this is far more accurate than its sign needs.
    double m[4][4];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[r][c] = object_to_clip.at(r, c);
    const double s0 = m[0][0] * m[1][1] - m[1][0] * m[0][1], s1 = m[0][0] * m[1][2] - m[1][0] * m[0][2];
    const double s2 = m[0][0] * m[1][3] - m[1][0] * m[0][3], s3 = m[0][1] * m[1][2] - m[1][1] * m[0][2];
    const double s4 = m[0][1] * m[1][3] - m[1][1] * m[0][3], s5 = m[0][2] * m[1][3] - m[1][2] * m[0][3];
    const double c5 = m[2][2] * m[3][3] - m[3][2] * m[2][3], c4 = m[2][1] * m[3][3] - m[3][1] * m[2][3];
    const double c3 = m[2][1] * m[3][2] - m[3][1] * m[2][2], c2 = m[2][0] * m[3][3] - m[3][0] * m[2][3];
    const double c1 = m[2][0] * m[3][2] - m[3][0] * m[2][2], c0 = m[2][0] * m[3][1] - m[3][0] * m[2][1];
    const double det = s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0;
    if (!std::isfinite(det) || det == 0.0 || !std::isfinite(alpha) || alpha == 0.0f) return 0;
    return (det > 0) == (alpha > 0) ? 1 : -1;
}

namespace ptp_detail {

bool ptp_clip_rows(const Mat4& object_to_clip, float alpha, PtpClipRows& out) {
    const int sign = ptp_orientation_sign(object_to_clip, alpha);
    if (sign == 0) return false;
    const float s = static_cast<float>(sign);
    const int src_row[3] = {0, 1, 3};  // x, y, w
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) out.r[r][c] = s * object_to_clip.at(src_row[r], c);
    return true;
}

}  // namespace ptp_detail

namespace {

using ptp_detail::kPairCount;
using ptp_detail::kSchedule;

struct Pt {
    float x, y, w;
};

// a*b - c*d as fma(a, b, -(c*d)). Written with an explicit fma because GCC contracts a plain
// a*b - c*d into an fma on its own even in ISO C++ mode (-ffp-contract=fast is its C++ default),
// differently per target; a product that feeds an explicit fma is never contracted.
inline float minor2(float a, float b, float c, float d) {
    const float q = c * d;
    return std::fma(a, b, -q);
}

// Step 1: the clip-space points (rows x, y, w) of the patch whose point k is X[k], Y[k], Z[k], W[k].
inline __attribute__((always_inline)) void clip_points(const float* X, const float* Y, const float* Z, const float* W,
                                                       const ptp_detail::PtpClipRows& rows, Pt P[16]) {
    for (int k = 0; k < 16; ++k) {
        float o[3];
        for (int r = 0; r < 3; ++r) {
            float v = rows.r[r][0] * X[k];
            v = std::fma(rows.r[r][1], Y[k], v);
            v = std::fma(rows.r[r][2], Z[k], v);
            o[r] = std::fma(rows.r[r][3], W[k], v);
        }
        P[k] = {o[0], o[1], o[2]};
    }
}

// Steps 2-3: the 64 clip-space control plane z components.
inline __attribute__((always_inline)) void control_planes_z(const Pt P[16], float t[64]) {
    float mxy[kPairCount], mxw[kPairCount], myw[kPairCount];
    for (int q = 0; q < kPairCount; ++q) {
        // Minors of (a, b - a): equal to those of (a, b), and exactly 0 when b == a.
        const Pt a = P[kSchedule.pairs[q].a], b = P[kSchedule.pairs[q].b];
        const Pt e{b.x - a.x, b.y - a.y, b.w - a.w};
        mxy[q] = minor2(a.x, e.y, a.y, e.x);
        mxw[q] = minor2(a.x, e.w, a.w, e.x);
        myw[q] = minor2(a.y, e.w, a.w, e.y);
    }
    for (int d = 0; d < 64; ++d) {
        float acc = 0.0f;
        const int ci = kSchedule.corner_of_dest[d];
        if (ci >= 0) {
            const ptp_detail::Corner& cr = kSchedule.corners[ci];
            const Pt a = P[cr.a], b = P[cr.b], c = P[cr.c];
            const Pt d1{b.x - a.x, b.y - a.y, b.w - a.w}, d2{c.x - a.x, c.y - a.y, c.w - a.w};
            const float m_xy = minor2(a.x, d1.y, a.y, d1.x);
            const float m_xw = minor2(a.x, d1.w, a.w, d1.x);
            const float m_yw = minor2(a.y, d1.w, a.w, d1.y);
            float v = d2.x * m_yw;
            v = std::fma(-d2.y, m_xw, v);
            v = std::fma(d2.w, m_xy, v);
            acc = std::fma(cr.weight, v, acc);
        } else {
            for (int s = kSchedule.dest_first[d]; s < kSchedule.dest_first[d + 1]; ++s) {
                const ptp_detail::Step st = kSchedule.steps[s];
                const Pt c = P[st.third];
                float v = c.x * myw[st.pair];
                v = std::fma(-c.y, mxw[st.pair], v);
                v = std::fma(c.w, mxy[st.pair], v);
                acc = std::fma(st.weight, v, acc);
            }
        }
        t[d] = acc;
    }
}

// Step 4's rounding-error margins thr[64] (ptp_schedule.h, "Rounding-error margin"); false when
// the patch has a non-finite coordinate (then it is kept).
inline __attribute__((always_inline)) bool rounding_margins(const float* X, const float* Y, const float* Z,
                                                            const float* W, const Pt P[16],
                                                            const ptp_detail::PtpClipRows& rows, float thr[64]) {
    using namespace ptp_detail;
    float mx = 0.0f, my = 0.0f, mz = 0.0f, mw = 0.0f;
    for (int k = 0; k < 16; ++k) {
        mx = std::max(mx, std::fabs(X[k]));
        my = std::max(my, std::fabs(Y[k]));
        mz = std::max(mz, std::fabs(Z[k]));
        mw = std::max(mw, std::fabs(W[k]));
    }
    const float magnitude_sum = (mx + my) + (mz + mw);
    if (!(magnitude_sum <= std::numeric_limits<float>::max())) return false;
    float row_bound[3];
    for (int r = 0; r < 3; ++r) {
        float v = std::fabs(rows.r[r][0]) * mx;
        v = std::fma(std::fabs(rows.r[r][1]), my, v);
        v = std::fma(std::fabs(rows.r[r][2]), mz, v);
        row_bound[r] = std::fma(std::fabs(rows.r[r][3]), mw, v);
    }
    const float R = std::max(std::max(row_bound[0], row_bound[1]), row_bound[2]);
    Pt lo = P[0], hi = P[0];
    for (int k = 1; k < 16; ++k) {
        lo = {std::min(lo.x, P[k].x), std::min(lo.y, P[k].y), std::min(lo.w, P[k].w)};
        hi = {std::max(hi.x, P[k].x), std::max(hi.y, P[k].y), std::max(hi.w, P[k].w)};
    }
    const float E = std::max(std::max(hi.x - lo.x, hi.y - lo.y), hi.w - lo.w);
    const float RR = R * R;
    const float RRE = RR * E, RRR = RR * R, RE = R * E;
    const float REE = RE * E;
    float g1 = std::fma(kMarginUnderflow, RR, kMarginUnderflow);
    g1 = std::fma(kMarginC3, RRR, g1);
    g1 = std::fma(kMarginC1, RRE, g1);
    const float g2 = kMarginC2 * REE;
    unsigned collapsed = 0;
    for (int e = 0; e < 4; ++e) {
        const int a = kEdgePoints[e][0];
        bool same = true;
        for (int i = 1; i < 4; ++i) {
            const int b = kEdgePoints[e][i];
            same = same && X[b] == X[a] && Y[b] == Y[a] && Z[b] == Z[a] && W[b] == W[a];
        }
        collapsed |= same ? 1u << e : 0u;
    }
    for (int d = 0; d < 64; ++d) {
        const float scaled = kMarginWeights.weight[d] * g1;
        const float margin = std::fma(kMarginWeights.weight_terms[d], g2, scaled);
        thr[d] = (dest_edges(d) & collapsed) ? 0.0f : margin;
    }
    return true;
}

// The decision of step 4 for one patch.
inline __attribute__((always_inline)) bool decide(const float* X, const float* Y, const float* Z, const float* W,
                                                  const ptp_detail::PtpClipRows& rows, bool pcnt) {
    Pt P[16];
    float t[64], thr[64];
    clip_points(X, Y, Z, W, rows, P);
    control_planes_z(P, t);
    if (!rounding_margins(X, Y, Z, W, P, rows, thr)) return false;
    bool cull = true;
    for (int d = 0; d < 64; ++d) cull = cull && (pcnt ? t[d] <= -thr[d] : t[d] < -thr[d]);
    return cull;
}

}  // namespace

namespace ptp_detail {

PATCHCULL_SCALAR_CLONES
void ptp_control_planes_z(const BezierPatch& patch, const PtpClipRows& rows, float t[64]) {
    float X[16], Y[16], Z[16], W[16];
    for (int k = 0; k < 16; ++k) X[k] = patch.cp[k].x, Y[k] = patch.cp[k].y, Z[k] = patch.cp[k].z, W[k] = patch.cp[k].w;
    Pt P[16];
    clip_points(X, Y, Z, W, rows, P);
    control_planes_z(P, t);
}

PATCHCULL_SCALAR_CLONES
bool ptp_rounding_margins(const BezierPatch& patch, const PtpClipRows& rows, float thr[64]) {
    float X[16], Y[16], Z[16], W[16];
    for (int k = 0; k < 16; ++k) X[k] = patch.cp[k].x, Y[k] = patch.cp[k].y, Z[k] = patch.cp[k].z, W[k] = patch.cp[k].w;
    Pt P[16];
    clip_points(X, Y, Z, W, rows, P);
    return rounding_margins(X, Y, Z, W, P, rows, thr);
}

}  // namespace ptp_detail

PATCHCULL_SCALAR_CLONES
void cull_ptp_scalar(const PatchBatchView& patches, const Mat4& object_to_clip, float alpha, PtpRule rule,
                     std::uint8_t* culled) {
    ptp_detail::PtpClipRows rows;
    if (!ptp_detail::ptp_clip_rows(object_to_clip, alpha, rows)) {
        if (patches.count) std::memset(culled, 0, patches.count);
        return;
    }
    const bool pcnt = rule == PtpRule::pcnt;
    for (std::size_t p = 0; p < patches.count; ++p) {
        float X[16], Y[16], Z[16], W[16];
        for (int k = 0; k < 16; ++k) {
            X[k] = patches.at(p, k, 0), Y[k] = patches.at(p, k, 1);
            Z[k] = patches.at(p, k, 2), W[k] = patches.at(p, k, 3);
        }
        culled[p] = decide(X, Y, Z, W, rows, pcnt) ? 1 : 0;
    }
}

}  // namespace patchcull
