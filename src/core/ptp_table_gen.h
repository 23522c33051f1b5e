// Generator of Loop, Niessner & Eisenacher's parametric tangent plane table (private to patchcull; used by
// gen/gen_ptp_table.cpp to write src/core/ptp_table.inc and by tests/core/ptp_test.cpp to check
// that the checked-in table is what the definition gives).
//
// T(u,v) = cross4(B, B_u, B_v) is expanded symbolically over the 16 control points in exact
// rational arithmetic (see ptp_table_gen.cpp), merged per sorted triple j < k < l of control point
// indices (cross4 is trilinear and antisymmetric), written in Bernstein form of bidegree (8,8) and
// degree-reduced, exactly, to bidegree (7,7). The result is the list of non-zero terms
//   t[dest] += weight * cross4(cp[j], cp[k], cp[l]),   dest = 8*jv + iu in 0..63,
// with control points indexed as in patch.h (cp[4*j + i], i along u) and the control plane of
// T at (iu, jv) (iu along u) stored at dest = 8*jv + iu, i.e. T(u,v) = sum B7_iu(u) B7_jv(v) t[dest].
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace patchcull::ptp_gen {

/// Exact rational num/den (den > 0, gcd 1). Arithmetic is overflow-checked: an overflow throws
/// std::overflow_error (the generator's values are small; this never happens in practice).
struct Rational {
    std::int64_t num = 0;
    std::int64_t den = 1;
};

Rational make_rational(std::int64_t num, std::int64_t den = 1);
Rational operator+(Rational a, Rational b);
Rational operator-(Rational a, Rational b);
Rational operator*(Rational a, Rational b);
Rational operator/(Rational a, Rational b);
inline bool operator==(Rational a, Rational b) { return a.num == b.num && a.den == b.den; }
inline bool is_zero(Rational a) { return a.num == 0; }

struct Term {
    int dest = 0;             ///< control plane index 8*jv + iu
    int j = 0, k = 0, l = 0;  ///< control point indices, j < k < l
    Rational weight;
};

struct Expansion {
    std::vector<Term> terms;       ///< canonical order: by dest, then (j, k, l)
    int triples_considered = 0;    ///< sorted triples whose coefficient polynomial is non-zero
    bool reduced_exactly = false;  ///< every bidegree-8 coefficient polynomial degree-reduced exactly to 7
    int max_abs_numerator = 0;     ///< of the degree-8 coefficients, for the record
};

/// Expands cross4(B, B_u, B_v) as described above. Throws std::logic_error when a coefficient
/// polynomial does not degree-reduce exactly (it must: Loop, Niessner & Eisenacher §3).
Expansion expand_ptp();

/// Number of terms per destination as an 8x8 matrix, row jv, column iu (Loop, Niessner & Eisenacher §6's matrix).
std::vector<int> terms_per_destination(const std::vector<Term>& terms);

/// Orders terms for Loop, Niessner & Eisenacher §6's 16 threads per patch: thread tau = 4*(jv % 4) + (iu % 4) owns
/// the 4 destinations {iu, iu+4} x {jv, jv+4} (the four 4x4 quadrants summed: 31..33 terms per
/// thread). Position p of the result is executed in round p / 16 by lane p % 16 (the seed's loop
/// `for (k = tid; k < 516; k += 16)`): rounds 0..30 hold one term of each lane's own block; round
/// 31 holds the 32nd term of the 12 blocks that have one, and in the 4 lanes whose blocks have
/// only 31 terms the 33rd term of four 33-term blocks; round 32 (lanes 0..3) the remaining four
/// 33rd terms. No two terms of one round write the same destination (no write hazard between
/// the 16 lanes); throws std::logic_error if that cannot be arranged.
std::vector<Term> order_for_16_lanes(const std::vector<Term>& canonical);

/// True when no round of 16 consecutive positions writes a destination twice.
bool rounds_are_hazard_free(const std::vector<Term>& ordered);

/// The complete text of src/core/ptp_table.inc (header comment + one row per term).
std::string table_inc_text(const std::vector<Term>& ordered);

}  // namespace patchcull::ptp_gen
