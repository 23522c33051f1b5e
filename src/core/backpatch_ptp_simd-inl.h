// The ptp back-patch kernel's per-target body, shared by its two translation units
// (backpatch_ptp_simd.cpp: the ncnt rule and the entry; backpatch_ptp_pcnt_simd.cpp: the pcnt
// rule), so that the compiler builds the two fully unrolled rules in parallel; private to
// patchcull. See backpatch_ptp_simd.cpp for the arithmetic contract.
//
// A Highway "-inl.h" header, included at file scope once per target after <hwy/highway.h> (it
// opens patchcull::HWY_NAMESPACE itself), hence the toggling include guard, not #pragma once.
#if defined(PATCHCULL_CORE_BACKPATCH_PTP_SIMD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATCHCULL_CORE_BACKPATCH_PTP_SIMD_INL_H_
#undef PATCHCULL_CORE_BACKPATCH_PTP_SIMD_INL_H_
#else
#define PATCHCULL_CORE_BACKPATCH_PTP_SIMD_INL_H_
#endif

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>

#include "core/ptp_internal.h"
#include "core/ptp_schedule.h"
#include "core/simd_groups-inl.h"

HWY_BEFORE_NAMESPACE();
namespace patchcull {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace ptp {

using ptp_detail::kPairCount;
using ptp_detail::kSchedule;
using simd_groups::DF;
using simd_groups::Fma;
using simd_groups::FmaSub;
using simd_groups::ForEachGroup;
using simd_groups::Group;
using simd_groups::MF;
using simd_groups::NegFma;
using simd_groups::VF;

// a*b - c*e as fma(a, b, -(c*e)), like minor2 in backpatch_ptp.cpp. (A plain Sub(Mul, Mul) would not do:
// GCC contracts it into an fma on FMA targets, but not on the others.)
HWY_INLINE VF Minor(DF d, VF a, VF b, VF c, VF e) { return FmaSub(d, a, b, hn::Mul(c, e)); }

template <class F, std::size_t... I>
HWY_INLINE void Unroll(std::index_sequence<I...>, F&& f) {
    (f(std::integral_constant<std::size_t, I>{}), ...);
}

// The rounding-error margins' per-patch scales (backpatch_ptp.cpp's rounding_margins, same operations in
// the same order): g1, g2, the collapsed-edge masks and whether every coordinate is finite.
struct MarginScales {
    VF g1, g2;
    MF collapsed[4];
    MF finite;
};

HWY_INLINE MarginScales PatchMarginScales(DF d, const Group& g, const ptp_detail::PtpClipRows& rows, const VF* px,
                                          const VF* py, const VF* pw) {
    using namespace ptp_detail;
    MarginScales m;
    VF mag[4] = {hn::Zero(d), hn::Zero(d), hn::Zero(d), hn::Zero(d)};
    for (int k = 0; k < 16; ++k)
        for (int c = 0; c < 4; ++c) mag[c] = hn::Max(mag[c], hn::Abs(g.load(d, k, c)));
    const VF magnitude_sum = hn::Add(hn::Add(mag[0], mag[1]), hn::Add(mag[2], mag[3]));
    m.finite = hn::Le(magnitude_sum, hn::Set(d, std::numeric_limits<float>::max()));
    VF row_bound[3];
    for (int r = 0; r < 3; ++r) {
        VF v = hn::Mul(hn::Set(d, std::fabs(rows.r[r][0])), mag[0]);
        v = Fma(d, hn::Set(d, std::fabs(rows.r[r][1])), mag[1], v);
        v = Fma(d, hn::Set(d, std::fabs(rows.r[r][2])), mag[2], v);
        row_bound[r] = Fma(d, hn::Set(d, std::fabs(rows.r[r][3])), mag[3], v);
    }
    const VF R = hn::Max(hn::Max(row_bound[0], row_bound[1]), row_bound[2]);
    VF lox = px[0], loy = py[0], low = pw[0], hix = px[0], hiy = py[0], hiw = pw[0];
    for (int k = 1; k < 16; ++k) {
        lox = hn::Min(lox, px[k]), loy = hn::Min(loy, py[k]), low = hn::Min(low, pw[k]);
        hix = hn::Max(hix, px[k]), hiy = hn::Max(hiy, py[k]), hiw = hn::Max(hiw, pw[k]);
    }
    const VF E = hn::Max(hn::Max(hn::Sub(hix, lox), hn::Sub(hiy, loy)), hn::Sub(hiw, low));
    const VF RR = hn::Mul(R, R);
    const VF RRE = hn::Mul(RR, E), RRR = hn::Mul(RR, R), RE = hn::Mul(R, E);
    const VF REE = hn::Mul(RE, E);
    const VF uf = hn::Set(d, kMarginUnderflow);
    VF g1 = Fma(d, uf, RR, uf);
    g1 = Fma(d, hn::Set(d, kMarginC3), RRR, g1);
    m.g1 = Fma(d, hn::Set(d, kMarginC1), RRE, g1);
    m.g2 = hn::Mul(hn::Set(d, kMarginC2), REE);
    for (int e = 0; e < 4; ++e) {
        const int a = kEdgePoints[e][0];
        MF same = hn::FirstN(d, hn::Lanes(d));
        for (int i = 1; i < 4; ++i) {
            const int b = kEdgePoints[e][i];
            for (int c = 0; c < 4; ++c) same = hn::And(same, hn::Eq(g.load(d, b, c), g.load(d, a, c)));
        }
        m.collapsed[e] = same;
    }
    return m;
}

template <bool kPcnt>
HWY_INLINE MF PtpGroup(DF d, const Group& g, const ptp_detail::PtpClipRows& rows) {
    VF px[16], py[16], pw[16];
    {
        VF r[3][4];
        for (int i = 0; i < 3; ++i)
            for (int c = 0; c < 4; ++c) r[i][c] = hn::Set(d, rows.r[i][c]);
        for (int k = 0; k < 16; ++k) {
            const VF X = g.load(d, k, 0), Y = g.load(d, k, 1), Z = g.load(d, k, 2), W = g.load(d, k, 3);
            VF o[3];
            for (int i = 0; i < 3; ++i) {
                VF v = hn::Mul(r[i][0], X);
                v = Fma(d, r[i][1], Y, v);
                v = Fma(d, r[i][2], Z, v);
                o[i] = Fma(d, r[i][3], W, v);
            }
            px[k] = o[0], py[k] = o[1], pw[k] = o[2];
        }
    }
    const MarginScales margin = PatchMarginScales(d, g, rows, px, py, pw);
    VF mxy[kPairCount], mxw[kPairCount], myw[kPairCount];
    Unroll(std::make_index_sequence<kPairCount>{}, [&](auto q) {
        constexpr int a = kSchedule.pairs[decltype(q)::value].a, b = kSchedule.pairs[decltype(q)::value].b;
        constexpr int qi = decltype(q)::value;
        const VF ex = hn::Sub(px[b], px[a]), ey = hn::Sub(py[b], py[a]), ew = hn::Sub(pw[b], pw[a]);
        mxy[qi] = Minor(d, px[a], ey, py[a], ex);
        mxw[qi] = Minor(d, px[a], ew, pw[a], ex);
        myw[qi] = Minor(d, py[a], ew, pw[a], ey);
    });
    const VF zero = hn::Zero(d);
    MF cull = margin.finite;
    Unroll(std::make_index_sequence<64>{}, [&](auto dd) {
        constexpr int dest = decltype(dd)::value;
        VF acc = zero;
        constexpr int ci = kSchedule.corner_of_dest[dest];
        if constexpr (ci >= 0) {
            constexpr ptp_detail::Corner cr = kSchedule.corners[ci];
            const VF d1x = hn::Sub(px[cr.b], px[cr.a]), d1y = hn::Sub(py[cr.b], py[cr.a]);
            const VF d1w = hn::Sub(pw[cr.b], pw[cr.a]);
            const VF d2x = hn::Sub(px[cr.c], px[cr.a]), d2y = hn::Sub(py[cr.c], py[cr.a]);
            const VF d2w = hn::Sub(pw[cr.c], pw[cr.a]);
            const VF m_xy = Minor(d, px[cr.a], d1y, py[cr.a], d1x);
            const VF m_xw = Minor(d, px[cr.a], d1w, pw[cr.a], d1x);
            const VF m_yw = Minor(d, py[cr.a], d1w, pw[cr.a], d1y);
            VF v = hn::Mul(d2x, m_yw);
            v = NegFma(d, d2y, m_xw, v);
            v = Fma(d, d2w, m_xy, v);
            acc = Fma(d, hn::Set(d, cr.weight), v, acc);
        } else {
            constexpr int first = kSchedule.dest_first[dest];
            constexpr int n = kSchedule.dest_first[dest + 1] - first;
            Unroll(std::make_index_sequence<n>{}, [&](auto s) {
                constexpr ptp_detail::Step st = kSchedule.steps[first + decltype(s)::value];
                VF v = hn::Mul(px[st.third], myw[st.pair]);
                v = NegFma(d, py[st.third], mxw[st.pair], v);
                v = Fma(d, pw[st.third], mxy[st.pair], v);
                acc = Fma(d, hn::Set(d, st.weight), v, acc);
            });
        }
        // thr = fma(W_d (K_d + 12), g2, W_d g1), 0 where one of the destination's edges collapsed.
        const VF scaled = hn::Mul(hn::Set(d, ptp_detail::kMarginWeights.weight[dest]), margin.g1);
        VF thr = Fma(d, hn::Set(d, ptp_detail::kMarginWeights.weight_terms[dest]), margin.g2, scaled);
        constexpr unsigned edges = ptp_detail::dest_edges(dest);
        for (int e = 0; e < 4; ++e)
            if (edges & (1u << e)) thr = hn::IfThenZeroElse(margin.collapsed[e], thr);
        const VF neg_thr = hn::Neg(thr);
        cull = hn::And(cull, kPcnt ? hn::Le(acc, neg_thr) : hn::Lt(acc, neg_thr));
    });
    return cull;
}

template <bool kPcnt>
HWY_NOINLINE void CullGroups(const PatchBatchView& patches, const ptp_detail::PtpClipRows& rows, std::uint8_t* culled) {
    // Compute-bound: software prefetching costs more than it saves (simd_groups-inl.h).
    ForEachGroup<false>(patches, culled, [&rows](DF d, const Group& g, std::size_t, std::size_t) {
        return PtpGroup<kPcnt>(d, g, rows);
    });
}

}  // namespace ptp

}  // namespace HWY_NAMESPACE
}  // namespace patchcull
HWY_AFTER_NAMESPACE();

#endif  // PATCHCULL_CORE_BACKPATCH_PTP_SIMD_INL_H_
