// Loop, Niessner & Eisenacher's parametric tangent plane table from its definition, in exact rational arithmetic
// (ptp_table_gen.h).
//
// Derivation. With B(u,v) = sum_a R0_a(u,v) b_a, B_u = sum_a R1_a b_a, B_v = sum_a R2_a b_a over
// the 16 control points b_a (a = 4*m + i, i along u, m along v), where
//   R0_a = B3_i(u) B3_m(v),  R1_a = B3_i'(u) B3_m(v),  R2_a = B3_i(u) B3_m'(v),
// trilinearity gives T = sum_{a,b,c} R0_a R1_b R2_c cross4(b_a, b_b, b_c), and antisymmetry merges
// the 6 orderings of each triple: T = sum_{j<k<l} P_jkl(u,v) cross4(b_j, b_k, b_l) with
//   P_jkl = det [[R0_j R0_k R0_l], [R1_j R1_k R1_l], [R2_j R2_k R2_l]]
// (triples with a repeated index vanish). Each product of the determinant is a tensor product of
// three univariate Bernstein polynomials in u (degrees 3, 2, 3) and three in v (3, 3, 2), so it
// has an exact Bernstein form of bidegree (8,8), by B^m_r B^n_s = C(m,r) C(n,s) / C(m+n,r+s)
// B^{m+n}_{r+s}. Degree reduction 8 -> 7 in u then in v inverts degree elevation
//   c8_r = (r/8) c7_{r-1} + (1 - r/8) c7_r   (r = 0..8):
// c7 is solved from the left (c7_0 = c8_0, c7_r = (8 c8_r - r c7_{r-1}) / (8 - r)) and then
// re-elevated; the reduction is exact iff all 9 re-elevated coefficients equal c8 (checked for
// every triple and both directions). The cross4 products of distinct sorted triples are linearly
// independent functions of the control points, so T has bidegree 7 iff every P_jkl does.
#include "core/ptp_table_gen.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace patchcull::ptp_gen {
namespace {

using i128 = __int128;

std::int64_t checked(i128 v) {
    if (v > INT64_MAX || v < -INT64_MAX) throw std::overflow_error("ptp_gen: rational overflow");
    return static_cast<std::int64_t>(v);
}

i128 gcd128(i128 a, i128 b) {
    if (a < 0) a = -a;
    if (b < 0) b = -b;
    while (b != 0) {
        const i128 t = a % b;
        a = b;
        b = t;
    }
    return a;
}

Rational normalized(i128 num, i128 den) {
    if (den == 0) throw std::domain_error("ptp_gen: division by zero");
    if (den < 0) num = -num, den = -den;
    if (num == 0) return {0, 1};
    const i128 g = gcd128(num, den);
    return {checked(num / g), checked(den / g)};
}

std::int64_t binomial(int n, int k) {
    if (k < 0 || k > n) return 0;
    std::int64_t r = 1;
    for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
    return r;
}

// Univariate polynomial in Bernstein form of degree deg: coefficients c[0..deg].
struct Bern {
    int deg = 0;
    std::array<Rational, 9> c{};
};

Bern bernstein_basis(int deg, int i) {  // B^deg_i
    Bern b;
    b.deg = deg;
    b.c[i] = make_rational(1);
    return b;
}

Bern bernstein_derivative(int i) {  // d/dt B^3_i = 3 (B^2_{i-1} - B^2_i)
    Bern b;
    b.deg = 2;
    if (i - 1 >= 0) b.c[i - 1] = b.c[i - 1] + make_rational(3);
    if (i <= 2) b.c[i] = b.c[i] - make_rational(3);
    return b;
}

Bern multiply(const Bern& a, const Bern& b) {
    Bern r;
    r.deg = a.deg + b.deg;
    for (int s = 0; s <= a.deg; ++s)
        for (int t = 0; t <= b.deg; ++t) {
            if (is_zero(a.c[s]) || is_zero(b.c[t])) continue;
            const Rational f = make_rational(binomial(a.deg, s) * binomial(b.deg, t), binomial(r.deg, s + t));
            r.c[s + t] = r.c[s + t] + a.c[s] * b.c[t] * f;
        }
    return r;
}

// Exact degree reduction 8 -> 7 of c8[0..8] (stride-addressed); returns false if not exact.
template <class Get, class Put>
bool reduce_8_to_7(const Get& c8, const Put& put) {
    std::array<Rational, 8> c7{};
    c7[0] = c8(0);
    for (int r = 1; r <= 7; ++r)
        c7[r] = (make_rational(8) * c8(r) - make_rational(r) * c7[r - 1]) / make_rational(8 - r);
    for (int r = 0; r <= 8; ++r) {
        Rational e = make_rational(0);
        if (r >= 1) e = e + make_rational(r, 8) * c7[r - 1];
        if (r <= 7) e = e + make_rational(8 - r, 8) * c7[r];
        if (!(e == c8(r))) return false;
    }
    for (int r = 0; r <= 7; ++r) put(r, c7[r]);
    return true;
}

}  // namespace

Rational make_rational(std::int64_t num, std::int64_t den) { return normalized(num, den); }
Rational operator+(Rational a, Rational b) {
    return normalized(static_cast<i128>(a.num) * b.den + static_cast<i128>(b.num) * a.den,
                      static_cast<i128>(a.den) * b.den);
}
Rational operator-(Rational a, Rational b) {
    return normalized(static_cast<i128>(a.num) * b.den - static_cast<i128>(b.num) * a.den,
                      static_cast<i128>(a.den) * b.den);
}
Rational operator*(Rational a, Rational b) {
    return normalized(static_cast<i128>(a.num) * b.num, static_cast<i128>(a.den) * b.den);
}
Rational operator/(Rational a, Rational b) {
    return normalized(static_cast<i128>(a.num) * b.den, static_cast<i128>(a.den) * b.num);
}

Expansion expand_ptp() {
    // Univariate factors per index i in 0..3: f (degree 3) and f' (degree 2).
    std::array<Bern, 4> f, df;
    for (int i = 0; i < 4; ++i) {
        f[i] = bernstein_basis(3, i);
        df[i] = bernstein_derivative(i);
    }
    Expansion out;
    out.reduced_exactly = true;
    for (int j = 0; j < 16; ++j)
        for (int k = j + 1; k < 16; ++k)
            for (int l = k + 1; l < 16; ++l) {
                // P = sum over orderings (a0, a1, a2) of (j, k, l) of sign * R0_a0 R1_a1 R2_a2.
                std::array<std::array<Rational, 9>, 9> p{};  // p[ru][rv], bidegree (8, 8)
                const int idx[3] = {j, k, l};
                const int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
                for (int q = 0; q < 6; ++q) {
                    const int sign = q < 3 ? 1 : -1;
                    const int a0 = idx[perms[q][0]], a1 = idx[perms[q][1]], a2 = idx[perms[q][2]];
                    // u: B3_i(a0) * B3'_i(a1) * B3_i(a2); v: B3_m(a0) * B3_m(a1) * B3'_m(a2).
                    const Bern U = multiply(multiply(f[a0 % 4], df[a1 % 4]), f[a2 % 4]);
                    const Bern V = multiply(multiply(f[a0 / 4], f[a1 / 4]), df[a2 / 4]);
                    for (int ru = 0; ru <= 8; ++ru)
                        for (int rv = 0; rv <= 8; ++rv) {
                            if (is_zero(U.c[ru]) || is_zero(V.c[rv])) continue;
                            const Rational t = U.c[ru] * V.c[rv];
                            p[ru][rv] = sign > 0 ? p[ru][rv] + t : p[ru][rv] - t;
                        }
                }
                bool nonzero = false;
                for (const auto& row : p)
                    for (const Rational& c : row) {
                        nonzero = nonzero || !is_zero(c);
                        out.max_abs_numerator =
                            std::max<int>(out.max_abs_numerator, static_cast<int>(c.num < 0 ? -c.num : c.num));
                    }
                if (!nonzero) continue;
                ++out.triples_considered;
                // Reduce in u for each rv (9 columns), then in v for each iu (8 rows).
                std::array<std::array<Rational, 9>, 8> pu{};  // pu[iu][rv]
                for (int rv = 0; rv <= 8; ++rv) {
                    const bool ok =
                        reduce_8_to_7([&](int r) { return p[r][rv]; }, [&](int r, Rational c) { pu[r][rv] = c; });
                    out.reduced_exactly = out.reduced_exactly && ok;
                }
                std::array<std::array<Rational, 8>, 8> p7{};  // p7[iu][jv]
                for (int iu = 0; iu < 8; ++iu) {
                    const bool ok =
                        reduce_8_to_7([&](int r) { return pu[iu][r]; }, [&](int r, Rational c) { p7[iu][r] = c; });
                    out.reduced_exactly = out.reduced_exactly && ok;
                }
                if (!out.reduced_exactly) throw std::logic_error("ptp_gen: T does not reduce to bidegree 7");
                for (int jv = 0; jv < 8; ++jv)
                    for (int iu = 0; iu < 8; ++iu)
                        if (!is_zero(p7[iu][jv])) out.terms.push_back({8 * jv + iu, j, k, l, p7[iu][jv]});
            }
    std::stable_sort(out.terms.begin(), out.terms.end(), [](const Term& a, const Term& b) {
        if (a.dest != b.dest) return a.dest < b.dest;
        if (a.j != b.j) return a.j < b.j;
        if (a.k != b.k) return a.k < b.k;
        return a.l < b.l;
    });
    return out;
}

std::vector<int> terms_per_destination(const std::vector<Term>& terms) {
    std::vector<int> m(64, 0);
    for (const Term& t : terms) ++m[t.dest];
    return m;
}

namespace {
int lane_of(int dest) { return 4 * ((dest / 8) % 4) + (dest % 8) % 4; }
}  // namespace

std::vector<Term> order_for_16_lanes(const std::vector<Term>& canonical) {
    // Each block's terms, taken round-robin over its 4 destinations (canonical order within one
    // destination), so a lane's consecutive terms mostly change destination.
    std::array<std::vector<Term>, 16> block;
    for (int lane = 0; lane < 16; ++lane) {
        std::array<std::vector<Term>, 4> per_dest;
        for (const Term& t : canonical)
            if (lane_of(t.dest) == lane) per_dest[((t.dest / 8) / 4) * 2 + (t.dest % 8) / 4].push_back(t);
        std::array<std::size_t, 4> next{};
        for (bool any = true; any;) {
            any = false;
            for (int q = 0; q < 4; ++q)
                if (next[q] < per_dest[q].size()) {
                    block[lane].push_back(per_dest[q][next[q]++]);
                    any = true;
                }
        }
        // The last two terms of a 33-term block may share round 31: make their destinations differ
        // (swap the second-to-last with the latest earlier term of another destination).
        auto& b = block[lane];
        if (b.size() >= 2 && b[b.size() - 1].dest == b[b.size() - 2].dest) {
            for (std::size_t q = b.size() - 2; q-- > 0;)
                if (b[q].dest != b.back().dest) {
                    std::swap(b[q], b[b.size() - 2]);
                    break;
                }
        }
    }
    std::size_t min_block = SIZE_MAX;
    for (const auto& b : block) min_block = std::min(min_block, b.size());
    std::vector<Term> out;
    out.reserve(canonical.size());
    // Rounds 0 .. min_block-1: each lane its own block.
    for (std::size_t r = 0; r < min_block; ++r)
        for (int lane = 0; lane < 16; ++lane) out.push_back(block[lane][r]);
    // Leftovers: first each block's next term in its own lane; lanes without one take surplus terms
    // (the last term of blocks that still have two), then the remaining surplus fills a last round.
    std::vector<Term> surplus;
    std::array<bool, 16> has_next{};
    std::array<Term, 16> next_term{};
    for (int lane = 0; lane < 16; ++lane) {
        const auto& b = block[lane];
        if (b.size() > min_block) has_next[lane] = true, next_term[lane] = b[min_block];
        for (std::size_t q = min_block + 1; q < b.size(); ++q) surplus.push_back(b[q]);
    }
    bool any_left = false;
    for (int lane = 0; lane < 16; ++lane) any_left = any_left || has_next[lane];
    if (any_left) {
        std::array<Term, 16> round{};
        std::array<bool, 16> filled{};
        for (int lane = 0; lane < 16; ++lane)
            if (has_next[lane]) round[lane] = next_term[lane], filled[lane] = true;
        std::size_t s = 0;
        for (int lane = 0; lane < 16 && s < surplus.size(); ++lane)
            if (!filled[lane]) round[lane] = surplus[s++], filled[lane] = true;
        // A round is a prefix of lanes: compact it (only the last round may be partial).
        for (int lane = 0; lane < 16; ++lane)
            if (filled[lane]) out.push_back(round[lane]);
        for (; s < surplus.size(); ++s) out.push_back(surplus[s]);
    }
    if (out.size() != canonical.size() || !rounds_are_hazard_free(out))
        throw std::logic_error("ptp_gen: no hazard-free 16-lane order");
    return out;
}

bool rounds_are_hazard_free(const std::vector<Term>& ordered) {
    for (std::size_t r = 0; r < ordered.size(); r += 16) {
        std::array<bool, 64> seen{};
        for (std::size_t p = r; p < std::min(ordered.size(), r + 16); ++p) {
            if (seen[ordered[p].dest]) return false;
            seen[ordered[p].dest] = true;
        }
    }
    return true;
}

std::string table_inc_text(const std::vector<Term>& ordered) {
    std::ostringstream s;
    const std::vector<int> m = terms_per_destination(ordered);
    s << "// src/core/ptp_table.inc: Loop, Niessner & Eisenacher's parametric tangent plane table (§5-6), "
         "GENERATED: do not edit.\n"
         "// Regenerate (after changing src/core/ptp_table_gen.cpp):\n"
         "//   cmake --build <build> --target patchcull_gen_ptp_table\n"
         "//   <build>/gen/patchcull_gen_ptp_table > src/core/ptp_table.inc\n"
         "// tests/core/ptp_test.cpp fails when this file differs from what the generator produces.\n"
         "//\n"
         "// T(u,v) = cross4(B, B_u, B_v) = sum_{iu,jv} B7_iu(u) B7_jv(v) t[8*jv + iu], with\n"
         "//   t[dest] = sum over the rows {dest, j, k, l, num, den} of (num/den) * cross4(cp[j], cp[k], cp[l]),\n"
         "// cp[4*j + i] as in patch.h (i along u), j < k < l, weights exact. Derived from the definition\n"
         "// in exact rational arithmetic; every bidegree-8 coefficient polynomial degree-reduces\n"
         "// exactly to bidegree 7.\n"
         "//\n"
         "// Order (Loop, Niessner & Eisenacher §6, 16 lanes per patch): row p runs in round p / 16 on lane "
         "p % 16. Lane\n"
         "// tau = 4*(jv%4) + (iu%4) owns destinations {iu, iu+4} x {jv, jv+4} (31..33 terms each);\n"
         "// rounds 0-30 hold one term of each lane's own block, round 31 the 32nd terms and, in the\n"
         "// lanes whose blocks have only 31, four 33rd terms; round 32 (lanes 0-3) the other four\n"
         "// 33rd terms. No round writes a destination twice (no shared-memory write hazard), so\n"
         "// `for (k = lane; k < "
      << ordered.size()
      << "; k += 16) t[dest_k] += w_k * cross4Z(...)` is race-free.\n"
         "//\n"
         "// Terms per destination (row jv, column iu):\n";
    for (int jv = 0; jv < 8; ++jv) {
        s << "//  ";
        for (int iu = 0; iu < 8; ++iu) {
            char buf[8];
            std::snprintf(buf, sizeof buf, " %2d", m[8 * jv + iu]);
            s << buf;
        }
        s << "\n";
    }
    s << "// " << ordered.size() << " terms: {dest, j, k, l, weight numerator, weight denominator}\n";
    for (std::size_t p = 0; p < ordered.size(); ++p) {
        const Term& t = ordered[p];
        s << "{" << t.dest << ", " << t.j << ", " << t.k << ", " << t.l << ", " << t.weight.num << ", " << t.weight.den
          << "},";
        s << ((p % 4 == 3 || p + 1 == ordered.size()) ? "\n" : " ");
    }
    return s.str();
}

}  // namespace patchcull::ptp_gen
