// The ptp kernels' evaluation schedule (private to patchcull; shared by backpatch_ptp.cpp and backpatch_ptp_simd.cpp so
// both do the same operations in the same order), derived at compile time from the generated
// table src/core/ptp_table.inc.
//
// The table: t[dest] = sum of 516 terms w * cross4Z(p_j, p_k, p_l) over clip-space control points,
// each sorted triple (j < k < l) in exactly one destination. cross4Z(a, b, c) is the 3x3
// determinant of the (x, y, w) columns a, b, c; expanded along its third column,
//   cross4Z(a, b, c) = c.x * m_yw(a,b) - c.y * m_xw(a,b) + c.w * m_xy(a,b),
//   m_xy(a,b) = a.x b.y - a.y b.x,  m_xw(a,b) = a.x b.w - a.w b.x,  m_yw(a,b) = a.y b.w - a.w b.y.
// Shared work: each term is computed from the 2x2 minors of one of its three point pairs (the
// third point then enters with 3 multiply-adds), and the pairs are chosen so that few distinct
// pairs are needed: 66 pairs cover the 512 non-corner terms (greedy set cover below; every sorted
// triple occurs in exactly one destination, and no pair twice in one destination, so grouping
// terms by pair or by destination shares nothing more). Per patch (FLOPs: fma = 2; in brackets
// the vector instructions):
//   clip transform, rows x, y, w: 16 x 3 x (mul + 3 fma)              =  336  [192]
//   minors: 66 pairs x (3 sub for b - a, 3 x (mul + fma))             =  792  [594]
//   terms: 512 x (mul + 2 fma for cross4Z, 1 fma with the weight)     = 3584 [2048]
//   corners: 4 x (6 sub + 3 x (mul + fma) + mul + 2 fma + fma)        =   88   [64]
//   total                                                             = 4800 [2898] + 64 compares
// against the seed's serial loop (516 full cross4Z: 3 minors (mul + fma) + mul + 2 fma, then the
// weighted fma: 16 FLOPs [10 instructions] each, 8256 [5160], + transform 336 [192] = 8592 [5352]):
// 44% fewer FLOPs, 46% fewer instructions.
//
// Exact zeros on collapsed edges (Loop, Niessner & Eisenacher §7's Pcnt rule for e.g. the teapot's lid): when a
// patch edge collapses to one point, T vanishes along it and its 8 boundary control planes are
// zero; they must come out as exactly 0 in floating point too, or a +tiny value blocks the Pcnt
// cull. Every term of a boundary destination has two points on that edge (T(u,0) depends only on
// B, B_u along v = 0), so:
// - the minors of a pair (a, b) are computed as the minors of (a, b - a) (the same values in exact
//   arithmetic): exactly 0 when b == a, since b - a is then the zero vector, whatever the rounding;
// - a non-corner boundary term uses the pair on its destination's edge;
// - the 4 corner terms (one per corner destination, e.g. 9 cross4Z(p0, p1, p4)) touch two edges:
//   they are computed as det[a, b - a, c - a] with a the corner (the "anchor"): exactly 0 when
//   b == a or c == a (a zero difference vector), whichever edge collapsed.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace patchcull::ptp_detail {

struct TableRow {
    int dest, j, k, l;
    long long num, den;
};

inline constexpr TableRow kTable[] = {
#include "core/ptp_table.inc"
};
inline constexpr int kTermCount = static_cast<int>(sizeof(kTable) / sizeof(kTable[0]));
static_assert(kTermCount == 516, "Loop, Niessner & Eisenacher: 516 weighted cross4 products");

struct Pair {
    std::uint8_t a, b;  // a < b
};
struct Step {  // acc += weight * cross4Z(p[pairs[pair].a], p[pairs[pair].b], p[third])
    std::uint8_t pair, third;
    float weight;  // table weight with the permutation sign folded in
};
struct Corner {  // t[dest] = weight * det[p_a, p_b - p_a, p_c - p_a]
    std::uint8_t dest, a, b, c;
    float weight;
};

struct Schedule {
    int num_pairs = 0;
    std::array<Pair, 120> pairs{};
    std::array<Step, kTermCount> steps{};        // grouped by destination, table order within
    std::array<std::uint16_t, 65> dest_first{};  // steps of dest d: [dest_first[d], dest_first[d+1])
    std::array<Corner, 4> corners{};
    std::array<std::int8_t, 64> corner_of_dest{};  // index into corners, or -1
};

namespace schedule_build {

constexpr bool is_corner_dest(int d) { return (d % 8 == 0 || d % 8 == 7) && (d / 8 == 0 || d / 8 == 7); }

// Whether control point a lies on the patch edge of boundary destination d (non-corner).
constexpr bool on_dest_edge(int d, int a) {
    const int iu = d % 8, jv = d / 8;
    if (jv == 0) return a / 4 == 0;
    if (jv == 7) return a / 4 == 3;
    if (iu == 0) return a % 4 == 0;
    if (iu == 7) return a % 4 == 3;
    return true;  // interior destination: any pair
}

constexpr int pair_index(int a, int b) {  // a < b, dense index in 0..119
    int idx = 0;
    for (int x = 0; x < a; ++x) idx += 15 - x;
    return idx + (b - a - 1);
}

// Sign of the permutation taking (j, k, l) to (x, y, z).
constexpr int perm_sign(int j, int k, int /*l*/, int x, int y, int z) {
    const int p[3] = {x == j ? 0 : x == k ? 1 : 2, y == j ? 0 : y == k ? 1 : 2, z == j ? 0 : z == k ? 1 : 2};
    int inv = 0;
    for (int s = 0; s < 3; ++s)
        for (int t = s + 1; t < 3; ++t) inv += p[s] > p[t];
    return inv % 2 ? -1 : 1;
}

constexpr Schedule make() {
    Schedule s;
    // Built for clang's constant evaluator, which gives up after 2^20 steps (-fconstexpr-steps; GCC's
    // limit is far higher): the scratch arrays are built-in arrays (each std::array::operator[] call
    // costs several steps), each term's candidate pairs are computed once, and the greedy passes visit
    // only the terms still uncovered. About 0.3 million steps (the plain version: over 2 million).
    // Candidate pairs per term: cand[t][q] is the pair index (pair_index) of {(j,k), (j,l), (k,l)}[q]
    // when both its points lie on the destination's edge, else -1; corner terms handled apart.
    int cand[kTermCount][3] = {};
    bool chosen[120] = {};
    for (int t = 0; t < kTermCount; ++t) {
        const TableRow& r = kTable[t];
        const int pa[3][2] = {{r.j, r.k}, {r.j, r.l}, {r.k, r.l}};
        for (int q = 0; q < 3; ++q)
            cand[t][q] =
                on_dest_edge(r.dest, pa[q][0]) && on_dest_edge(r.dest, pa[q][1]) ? pair_index(pa[q][0], pa[q][1]) : -1;
    }
    // Greedy set cover: forced pairs first, then repeatedly the pair covering most uncovered terms
    // (ties: lowest pair index). Deterministic. open[0, n_open): the terms not yet covered (a chosen
    // candidate pair covers a term for good), the non-corner terms at first, compacted on every pass.
    int open[kTermCount] = {};
    int n_open = 0;
    for (int t = 0; t < kTermCount; ++t) {
        if (is_corner_dest(kTable[t].dest)) continue;
        open[n_open++] = t;
        int n = 0, only = -1;
        for (int q = 0; q < 3; ++q)
            if (cand[t][q] >= 0) ++n, only = q;
        if (n == 0) throw "ptp schedule: boundary term without an edge pair";
        if (n == 1) chosen[cand[t][only]] = true;
    }
    for (;;) {
        int count[120] = {};
        int kept = 0;
        for (int i = 0; i < n_open; ++i) {
            const int t = open[i];
            bool covered = false;
            for (int q = 0; q < 3 && !covered; ++q) covered = cand[t][q] >= 0 && chosen[cand[t][q]];
            if (covered) continue;
            open[kept++] = t;
            for (int q = 0; q < 3; ++q)
                if (cand[t][q] >= 0) ++count[cand[t][q]];
        }
        n_open = kept;
        if (n_open == 0) break;
        int best = 0;
        for (int p = 1; p < 120; ++p)
            if (count[p] > count[best]) best = p;
        chosen[best] = true;
    }
    // Dense numbering of the chosen pairs, in pair index order.
    int slot[120] = {};
    for (int a = 0; a < 16; ++a)
        for (int b = a + 1; b < 16; ++b)
            if (chosen[pair_index(a, b)]) {
                slot[pair_index(a, b)] = s.num_pairs;
                s.pairs[s.num_pairs++] = Pair{static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b)};
            }
    // Steps grouped by destination (table order within one), corners apart.
    int n = 0, c = 0;
    for (int d = 0; d < 64; ++d) {
        s.dest_first[d] = static_cast<std::uint16_t>(n);
        s.corner_of_dest[d] = -1;
        for (int t = 0; t < kTermCount; ++t) {
            const TableRow& r = kTable[t];
            if (r.dest != d) continue;
            const float w = static_cast<float>(r.num) / static_cast<float>(r.den);
            if (is_corner_dest(d)) {
                // Anchor: the corner point of the destination's corner (shared by both edges).
                const int corner = (d % 8 == 0 ? 0 : 3) + 4 * (d / 8 == 0 ? 0 : 3);
                const int other[2] = {r.j == corner ? r.k : r.j, r.l == corner ? r.k : r.l};
                if (!(r.j == corner || r.k == corner || r.l == corner))
                    throw "ptp schedule: corner term without its corner";
                const int sign = perm_sign(r.j, r.k, r.l, corner, other[0], other[1]);
                s.corner_of_dest[d] = static_cast<std::int8_t>(c);
                s.corners[c++] =
                    Corner{static_cast<std::uint8_t>(d), static_cast<std::uint8_t>(corner),
                           static_cast<std::uint8_t>(other[0]), static_cast<std::uint8_t>(other[1]), sign > 0 ? w : -w};
                continue;
            }
            const int third[3] = {r.l, r.k, r.j};
            const int sign[3] = {1, -1, 1};  // det[j,k,l] = det[j,k,l] = -det[j,l,k] = det[k,l,j]
            int q = -1;
            for (int e = 0; e < 3 && q < 0; ++e)
                if (cand[t][e] >= 0 && chosen[cand[t][e]]) q = e;
            s.steps[n++] = Step{static_cast<std::uint8_t>(slot[cand[t][q]]), static_cast<std::uint8_t>(third[q]),
                                sign[q] > 0 ? w : -w};
        }
    }
    s.dest_first[64] = static_cast<std::uint16_t>(n);
    if (c != 4 || n != kTermCount - 4) throw "ptp schedule: unexpected term split";
    return s;
}

}  // namespace schedule_build

inline constexpr Schedule kSchedule = schedule_build::make();
inline constexpr int kPairCount = kSchedule.num_pairs;
inline constexpr int kStepCount = kTermCount - 4;

// ---- Rounding-error margin ----------------------------------------------------------------------
// The kernels cull only when every t[d] < -thr[d] (Ncnt) or <= -thr[d] (Pcnt), where thr[d]
// bounds |t[d] - t*[d]|, t*[d] being the exact value for the exact clip points M X of the patch's
// float control points X (M the float rows of s * object_to_clip) and the exact rational weights.
// Without it, distant nearly edge-on patches were culled with a tangent plane facing the eye by
// ~1e-5 rad (docs/RESULTS.md, Finding 1). Per patch (the same operations, in this order, in
// backpatch_ptp.cpp, backpatch_ptp_simd.cpp and backpatch_ptp.comp.glsl, so all three agree bit for bit):
//   Mc = max_k |X_k.c| (c = x, y, z, w), finite = (Mx + My) + (Mz + Mw) <= FLT_MAX
//   R  = max over rows i of fma chain |r_i0| Mx + |r_i1| My + |r_i2| Mz + |r_i3| Mw
//        (>= sum_c |r_ic| |X_k.c| for every point k: R bounds |P| and P's rounding scale)
//   E  = max over x, y, w of (max_k P - min_k P) (every clip-space difference is <= E)
//   RR = R R;  g1 = fma(kC1, RR E, fma(kC3, RR R, fma(kUf, RR, kUf)));  g2 = kC2 ((R E) E)
//   thr[d] = fma(margin_weight_terms[d], g2, margin_weight[d] g1), or 0 on a collapsed edge.
// Why it bounds the error (u = 2^-24; |det[x,y,z]| <= 6 |x| |y| |z| in the max norm over x, y, w):
// - P = M X by mul + 3 fma: |P - P*| <= eta R, eta = gamma_4 ~ 4u. With det[a,b,c] =
//   det[a, b - a, c - a] and |b - a| <= E, one term's sensitivity to these errors is
//   <= 24 eta R^2 E + 6 eta R E^2 + 24 eta^2 R^3;
// - the schedule's arithmetic on the computed P: a pair minor of (a, e = b - a) has error
//   <= 5u R E (e's rounding included) and magnitude <= 2 R E; cross4Z = c . m then errs by
//   <= 3 R 5u R E + u (2 + 4 + 6) R^2 E = 27u R^2 E (a corner, det[a, d1, d2] with |d2| <= E,
//   by <= 33u R E^2);
// - the weighted sum: |v| <= 6 R E^2 per term, so the K_d fma roundings and the float weight
//   add <= 6u (K_d + 1) W_d R E^2, W_d = sum of the destination's |weights|.
// Sum: W_d ((24 eta + 27u) R^2 E + 24 eta^2 R^3) + 6u W_d (K_d + 5) R E^2 (corners: 6u (K_d + 10)),
// covered by kC1 = 128u >= 123u, kC3 = 2^-38 >= 384 u^2, kC2 = 8u with margin_weight_terms =
// W_d (K_d + 12), all rounded up, leaving slack for the roundings of R, E and thr themselves.
// kUf covers underflow: each of the < 3000 operations may lose up to 2^-126 (flush to zero on
// GPUs included), amplified into t by < 54 W_d max(1, R^2). Non-finite inputs keep the patch
// (NaN or inf in t, thr, or `finite` false).
// Collapsed edges: when an edge's 4 control points are equal (object space, every component), its
// 8 destinations are computed as exact zeros (see above) and are exactly zero, so their thr is 0
// and Pcnt can still cull such patches. Edges: 0 = v0 (points 0-3, destinations jv = 0),
// 1 = u1 (3, 7, 11, 15; iu = 7), 2 = v1 (12-15; jv = 7), 3 = u0 (0, 4, 8, 12; iu = 0).
// The bound is about 100 times the largest error observed (tests/core/ptp_test.cpp: worst-case
// roundings against ones that partly cancel); its cost in culls is in docs/RESULTS.md.
inline constexpr float kMarginC1 = 0x1p-17f;  // 128 u
inline constexpr float kMarginC2 = 0x1p-21f;  // 8 u
inline constexpr float kMarginC3 = 0x1p-38f;  // >= 384 u^2
inline constexpr float kMarginUnderflow = 0x1p-100f;
inline constexpr int kEdgePoints[4][4] = {{0, 1, 2, 3}, {3, 7, 11, 15}, {12, 13, 14, 15}, {0, 4, 8, 12}};

/// Bit e set: destination d lies on edge e (kEdgePoints), 0 for interior destinations.
constexpr unsigned dest_edges(int d) {
    const int iu = d % 8, jv = d / 8;
    return (jv == 0 ? 1u : 0u) | (iu == 7 ? 2u : 0u) | (jv == 7 ? 4u : 0u) | (iu == 0 ? 8u : 0u);
}

struct MarginWeights {
    std::array<float, 64> weight{};        // W_d, rounded up
    std::array<float, 64> weight_terms{};  // W_d (K_d + 12), rounded up
};

namespace schedule_build {

// x rounded up to a float (conversion rounds to nearest; the factor lifts it above x).
constexpr float round_up(double x) { return static_cast<float>(x * (1.0 + 0x1p-20)); }

constexpr MarginWeights make_margin_weights() {
    MarginWeights m;
    for (int d = 0; d < 64; ++d) {
        double w = 0;
        int k = 0;
        for (const TableRow& r : kTable)
            if (r.dest == d) w += static_cast<double>(r.num < 0 ? -r.num : r.num) / static_cast<double>(r.den), ++k;
        m.weight[d] = round_up(w);
        m.weight_terms[d] = round_up(w * (k + 12));
    }
    return m;
}

}  // namespace schedule_build

inline constexpr MarginWeights kMarginWeights = schedule_build::make_margin_weights();

}  // namespace patchcull::ptp_detail
