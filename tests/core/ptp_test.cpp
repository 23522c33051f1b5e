// Parametric tangent plane back-patch culling (patchcull/core/backpatch.h; Loop, Niessner & Eisenacher,
// "Effective Back-Patch Culling for Hardware Tessellation" §3-6):
// - the table: generated in-process from the definition, equal to the checked-in ptp_table.inc,
//   516 terms with the paper's per-destination matrix, hazard-free 16-lane order;
// - T(u,v) from the 64 control planes equals cross4(B, B_u, B_v) computed directly (double, all 4
//   components, object space), for polynomial and rational patches; a mutated table fails that;
// - the kernels' compile-time schedule (shared minors, corner anchors) reproduces the table;
// - decisions are conservative against T sampled densely in double precision (random patches and
//   eyes, eyes close to the surface, collapsed edges, rational patches, the teapot, mirroring
//   model matrices), and Pcnt culls the teapot's degenerate top where Ncnt cannot;
// - scalar and every compiled SIMD target give identical decisions.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/ptp_internal.h"
#include "core/ptp_schedule.h"
#include "core/ptp_table_gen.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/teapot.h"

using namespace patchcull;

namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- double-precision reference geometry ------------------------------------------------------

struct D4 {
    double x = 0, y = 0, z = 0, w = 0;
};
D4 operator+(D4 a, D4 b) { return {a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w}; }
D4 operator*(double s, D4 a) { return {s * a.x, s * a.y, s * a.z, s * a.w}; }
double dot(D4 a, D4 b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }
double norm(D4 a) { return std::sqrt(dot(a, a)); }
D4 to_d(Vec4 p) { return {p.x, p.y, p.z, p.w}; }

double det3(double a, double b, double c, double d, double e, double f, double g, double h, double i) {
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
}

// Loop, Niessner & Eisenacher, Appendix A.
D4 cross4(D4 a, D4 b, D4 c) {
    return {det3(a.y, b.y, c.y, a.z, b.z, c.z, a.w, b.w, c.w), -det3(a.x, b.x, c.x, a.z, b.z, c.z, a.w, b.w, c.w),
            det3(a.x, b.x, c.x, a.y, b.y, c.y, a.w, b.w, c.w), -det3(a.x, b.x, c.x, a.y, b.y, c.y, a.z, b.z, c.z)};
}

double bernstein(int n, int i, double t) {
    double c = 1;
    for (int k = 1; k <= i; ++k) c = c * (n - i + k) / k;
    return c * std::pow(1 - t, n - i) * std::pow(t, i);
}
double bernstein3_derivative(int i, double t) {
    return 3 * ((i >= 1 ? bernstein(2, i - 1, t) : 0.0) - (i <= 2 ? bernstein(2, i, t) : 0.0));
}

// T(u,v) = cross4(B, B_u, B_v), directly.
D4 tangent_plane_direct(const BezierPatch& p, double u, double v) {
    D4 B, Bu, Bv;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const D4 c = to_d(p.cp[4 * j + i]);
            const double fu = bernstein(3, i, u), fv = bernstein(3, j, v);
            B = B + (fu * fv) * c;
            Bu = Bu + (bernstein3_derivative(i, u) * fv) * c;
            Bv = Bv + (fu * bernstein3_derivative(j, v)) * c;
        }
    return cross4(B, Bu, Bv);
}

struct TableTerm {
    int dest, j, k, l;
    double weight;
};

std::vector<TableTerm> compiled_table() {
    std::vector<TableTerm> t;
    for (const auto& r : ptp_detail::kTable)
        t.push_back({r.dest, r.j, r.k, r.l, static_cast<double>(r.num) / static_cast<double>(r.den)});
    return t;
}

// The 64 control planes (all 4 components) from a table, in double.
std::array<D4, 64> control_planes(const std::vector<TableTerm>& table, const BezierPatch& p) {
    std::array<D4, 64> t{};
    for (const TableTerm& r : table)
        t[r.dest] = t[r.dest] + r.weight * cross4(to_d(p.cp[r.j]), to_d(p.cp[r.k]), to_d(p.cp[r.l]));
    return t;
}

D4 evaluate_planes(const std::array<D4, 64>& t, double u, double v) {
    D4 T;
    for (int jv = 0; jv < 8; ++jv)
        for (int iu = 0; iu < 8; ++iu) T = T + (bernstein(7, iu, u) * bernstein(7, jv, v)) * t[8 * jv + iu];
    return T;
}

// Largest |T_table - T_direct| / scale over random (u, v); scale = max |T_direct| over the samples.
double max_relative_plane_error(const std::vector<TableTerm>& table, const BezierPatch& p, std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(0, 1);
    const std::array<D4, 64> t = control_planes(table, p);
    double worst = 0, scale = 0;
    std::vector<std::pair<D4, D4>> samples;
    for (int s = 0; s < 24; ++s) {
        const double u = s < 4 ? (s & 1) : unit(rng), v = s < 4 ? (s >> 1) : unit(rng);
        samples.push_back({evaluate_planes(t, u, v), tangent_plane_direct(p, u, v)});
        scale = std::max(scale, norm(samples.back().second));
    }
    for (const auto& [a, b] : samples) worst = std::max(worst, norm(a + (-1.0) * b));
    return scale > 0 ? worst / scale : worst;
}

// ---- patches ----------------------------------------------------------------------------------

// A curved sheet: centre c, spanning vectors a, b, bumps of relative size bump, weights in
// [wmin, wmax] (w = 1 when wmin == wmax == 1).
BezierPatch sheet(std::mt19937& rng, Vec3 c, float size, float bump, float wmin, float wmax) {
    std::uniform_real_distribution<float> u(-1, 1), w(wmin, wmax);
    const Vec3 a = Vec3{u(rng), u(rng), u(rng)} * size, b = Vec3{u(rng), u(rng), u(rng)} * size;
    BezierPatch p;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const Vec3 pt =
                c + a * (i / 3.0f - 0.5f) + b * (j / 3.0f - 0.5f) + Vec3{u(rng), u(rng), u(rng)} * (bump * size);
            p.cp[4 * j + i] = homogeneous(pt, wmin == wmax ? wmin : w(rng));
        }
    return p;
}

// Collapses edge e (0: v = 0, 1: u = 1, 2: v = 1, 3: u = 0) to its first control point.
BezierPatch collapse_edge(BezierPatch p, int e) {
    auto idx = [e](int k) {
        switch (e) {
            case 0:
                return k;
            case 1:
                return 4 * k + 3;
            case 2:
                return 12 + k;
            default:
                return 4 * k;
        }
    };
    for (int k = 1; k < 4; ++k) p.cp[idx(k)] = p.cp[idx(0)];
    return p;
}

// A mix: smooth sheets (polynomial, rational), wild random control points, collapsed edges.
BezierPatch random_patch(std::mt19937& rng, float spread) {
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    const Vec3 c{spread * u(rng), spread * u(rng), spread * u(rng)};
    const int kind = static_cast<int>(unit(rng) * 6);
    const float size = 0.3f + 2.0f * unit(rng);
    switch (kind) {
        case 0:
            return sheet(rng, c, size, 0.05f, 1, 1);
        case 1:
            return sheet(rng, c, size, 0.3f, 1, 1);
        case 2:
            return sheet(rng, c, size, 0.2f, 0.4f, 2.5f);
        case 3:
            return collapse_edge(sheet(rng, c, size, 0.15f, 1, 1), static_cast<int>(unit(rng) * 4) & 3);
        case 4:
            return collapse_edge(sheet(rng, c, size, 0.15f, 0.5f, 2.0f), static_cast<int>(unit(rng) * 4) & 3);
        default:
            return sheet(rng, c, size, 1.0f, 0.7f, 1.5f);  // wild, self-intersecting
    }
}

// ---- views ------------------------------------------------------------------------------------

struct View {
    Mat4 object_to_clip;
    float alpha;
};

// Perspective view of an eye (world space) looking at target; model maps object to world.
View make_view(Vec3 eye, Vec3 target, const Mat4& model = Mat4{}, float fovy_deg = 60) {
    const Mat4 proj = perspective(static_cast<float>(fovy_deg * kPi / 180), 1.5f, 0.05f, 500.0f);
    Vec3 up{0, 1, 0};
    const Vec3 f = target - eye;
    if (std::fabs(f.x) < 1e-3f && std::fabs(f.z) < 1e-3f) up = {1, 0, 0};
    return {proj * look_at(eye, target, up) * model, clip_space_eye_alpha(proj)};
}

// The object-space homogeneous eye of a view: M^-1 (0, 0, alpha, 0), solved in double.
D4 object_space_eye(const View& view) {
    double a[4][5];
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) a[r][c] = view.object_to_clip.at(r, c);
        a[r][4] = r == 2 ? view.alpha : 0.0;
    }
    for (int c = 0; c < 4; ++c) {
        int piv = c;
        for (int r = c + 1; r < 4; ++r)
            if (std::fabs(a[r][c]) > std::fabs(a[piv][c])) piv = r;
        for (int k = 0; k < 5; ++k) std::swap(a[c][k], a[piv][k]);
        for (int r = 0; r < 4; ++r) {
            if (r == c) continue;
            const double f = a[r][c] / a[c][c];
            for (int k = c; k < 5; ++k) a[r][k] -= f * a[c][k];
        }
    }
    return {a[0][4] / a[0][0], a[1][4] / a[1][1], a[2][4] / a[2][2], a[3][4] / a[3][3]};
}

Mat4 model_matrix(std::mt19937& rng, bool mirror) {
    std::uniform_real_distribution<float> u(-1, 1);
    const float ang = static_cast<float>(kPi) * u(rng);
    Mat4 m;  // rotation about y, non-uniform scale, translation, optional mirror in x
    m.at(0, 0) = std::cos(ang) * (mirror ? -1.3f : 1.3f);
    m.at(0, 2) = std::sin(ang);
    m.at(2, 0) = -std::sin(ang) * (mirror ? -1.3f : 1.3f);
    m.at(2, 2) = std::cos(ang);
    m.at(1, 1) = 0.8f;
    m.at(0, 3) = u(rng), m.at(1, 3) = u(rng), m.at(2, 3) = u(rng);
    return m;
}

// ---- kernels ------------------------------------------------------------------------------------

enum class Impl { kScalar, kSimd };

std::vector<std::uint8_t> run_ptp(Impl impl, const PatchBatchView& view, const View& v, PtpRule rule) {
    constexpr std::size_t kGuard = 64;
    std::vector<std::uint8_t> out(view.count + kGuard, 0xAB);
    (impl == Impl::kScalar ? cull_ptp_scalar : cull_ptp_simd)(view, v.object_to_clip, v.alpha, rule, out.data());
    for (std::size_t i = view.count; i < out.size(); ++i) EXPECT_EQ(out[i], 0xAB) << "wrote past count at " << i;
    out.resize(view.count);
    return out;
}

// Calls body(target) once per SIMD target compiled into the library and supported by this CPU,
// with the dispatch forced to that target; restores normal dispatch afterwards.
void for_each_simd_target(const std::function<void(std::int64_t)>& body) {
    for (std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(std::string("SIMD target ") + hwy::TargetName(target));
        body(target);
    }
    hwy::SetSupportedTargetsForTest(0);
}

// Largest e . T(u,v) / (|e| |T(u,v)|) over a grid x grid lattice (points where T vanishes count
// as 0): > 0 means some point of the patch faces the eye.
double max_facing(const BezierPatch& p, D4 e, int grid = 17) {
    double worst = -1;
    for (int b = 0; b < grid; ++b)
        for (int a = 0; a < grid; ++a) {
            const D4 T = tangent_plane_direct(p, a / double(grid - 1), b / double(grid - 1));
            const double n = norm(e) * norm(T);
            worst = std::max(worst, n > 0 ? dot(e, T) / n : 0.0);
        }
    return worst;
}

constexpr double kFacingTolerance = 1e-4;

// Debug + sanitizer builds (the ASan + UBSan run of scripts/test.sh) are ~30x slower: the heavy
// tests do less there (the Release run does all of it).
#if defined(__SANITIZE_ADDRESS__) || !defined(NDEBUG)
constexpr bool kSlowBuild = true;
#else
constexpr bool kSlowBuild = false;
#endif  // relative to |e| |T|: float rounding of the kernel

}  // namespace

// ---- (a) the table ----------------------------------------------------------------------------

TEST(PtpTable, DefinitionGives516TermsWithTheSeedMatrix) {
    const ptp_gen::Expansion e = ptp_gen::expand_ptp();
    EXPECT_TRUE(e.reduced_exactly);
    EXPECT_EQ(e.terms.size(), 516u);
    const std::vector<int> seed = {1,  2,  4, 5,  5,  4,  2,  1,  2,  4, 8, 10, 10, 8,  4,  2,  4,  8, 11, 17, 17, 11,
                                   8,  4,  5, 10, 17, 21, 21, 17, 10, 5, 5, 10, 17, 21, 21, 17, 10, 5, 4,  8,  11, 17,
                                   17, 11, 8, 4,  2,  4,  8,  10, 10, 8, 4, 2,  1,  2,  4,  5,  5,  4, 2,  1};
    EXPECT_EQ(ptp_gen::terms_per_destination(e.terms), seed);
    // Corner: T(0,0) = cross4(b0, 3(b1 - b0), 3(b4 - b0)) = 9 cross4(b0, b1, b4).
    EXPECT_EQ(e.terms[0].dest, 0);
    EXPECT_EQ(e.terms[0].j, 0);
    EXPECT_EQ(e.terms[0].k, 1);
    EXPECT_EQ(e.terms[0].l, 4);
    EXPECT_TRUE(e.terms[0].weight == ptp_gen::make_rational(9));
    for (const ptp_gen::Term& t : e.terms) {
        EXPECT_TRUE(t.j < t.k && t.k < t.l);
        EXPECT_FALSE(ptp_gen::is_zero(t.weight));
    }
}

TEST(PtpTable, CheckedInTableEqualsTheGeneratorOutput) {
    const ptp_gen::Expansion e = ptp_gen::expand_ptp();
    const std::vector<ptp_gen::Term> ordered = ptp_gen::order_for_16_lanes(e.terms);
    std::ifstream in(std::string(PATCHCULL_SOURCE_DIR) + "/src/core/ptp_table.inc");
    ASSERT_TRUE(in) << "src/core/ptp_table.inc";
    std::stringstream file;
    file << in.rdbuf();
    EXPECT_EQ(file.str(), ptp_gen::table_inc_text(ordered))
        << "regenerate: patchcull_gen_ptp_table > src/core/ptp_table.inc";
    // And the table compiled into the kernels is that list, row for row.
    ASSERT_EQ(ordered.size(), static_cast<std::size_t>(ptp_detail::kTermCount));
    for (std::size_t p = 0; p < ordered.size(); ++p) {
        const auto& r = ptp_detail::kTable[p];
        EXPECT_EQ(r.dest, ordered[p].dest);
        EXPECT_EQ(r.j, ordered[p].j);
        EXPECT_EQ(r.k, ordered[p].k);
        EXPECT_EQ(r.l, ordered[p].l);
        EXPECT_EQ(r.num, ordered[p].weight.num);
        EXPECT_EQ(r.den, ordered[p].weight.den);
    }
}

TEST(PtpTable, SixteenLaneOrderIsHazardFreeAndBalanced) {
    const std::vector<ptp_gen::Term> ordered = ptp_gen::order_for_16_lanes(ptp_gen::expand_ptp().terms);
    EXPECT_TRUE(ptp_gen::rounds_are_hazard_free(ordered));
    EXPECT_EQ((ordered.size() + 15) / 16, 33u);  // Loop, Niessner & Eisenacher §6: ceil(516 / 16) = 33 rounds
    // Rounds 0..30: lane tau works on its own block {iu, iu+4} x {jv, jv+4}.
    for (std::size_t p = 0; p < 31 * 16; ++p) {
        const int d = ordered[p].dest;
        EXPECT_EQ(static_cast<std::size_t>(4 * ((d / 8) % 4) + (d % 8) % 4), p % 16) << p;
    }
    // A permuted order that puts two writes to one destination in a round is detected.
    std::vector<ptp_gen::Term> bad = ordered;
    bool swapped = false;
    for (std::size_t p = 16; p < bad.size() && !swapped; ++p)
        if (bad[p].dest == bad[5].dest) std::swap(bad[6], bad[p]), swapped = true;
    ASSERT_TRUE(swapped);
    EXPECT_FALSE(ptp_gen::rounds_are_hazard_free(bad));
}

TEST(PtpTable, RationalArithmeticIsExactAndChecked) {
    using ptp_gen::make_rational;
    EXPECT_TRUE(make_rational(6, -4) == make_rational(-3, 2));
    EXPECT_TRUE(make_rational(1, 3) + make_rational(1, 6) == make_rational(1, 2));
    EXPECT_TRUE(make_rational(2, 7) / make_rational(4, 21) == make_rational(3, 2));
    EXPECT_THROW(make_rational(INT64_MAX / 2) * make_rational(4), std::overflow_error);
}

// ---- (b) T from the control planes ------------------------------------------------------------

TEST(PtpTable, ControlPlanesReproduceTheTangentPlane) {
    std::mt19937 rng(11);
    const std::vector<TableTerm> table = compiled_table();
    double worst = 0;
    for (int n = 0; n < 300; ++n) {
        const bool rational = n % 2 == 1;
        BezierPatch p =
            sheet(rng, {0, 0, 0}, 2.0f, n % 3 == 0 ? 1.0f : 0.2f, rational ? 0.3f : 1.0f, rational ? 3.0f : 1.0f);
        if (n % 5 == 4) p = collapse_edge(p, n % 4);
        worst = std::max(worst, max_relative_plane_error(table, p, rng));
    }
    for (const BezierPatch& p : teapot_patches()) worst = std::max(worst, max_relative_plane_error(table, p, rng));
    EXPECT_LT(worst, 1e-12);
}

// (e) The check above is sensitive: a table with one weight flipped, one term dropped or one term
// moved to another destination fails it.
TEST(PtpTable, MutatedTablesFailTheTangentPlaneCheck) {
    std::mt19937 rng(12);
    const std::vector<TableTerm> table = compiled_table();
    std::vector<BezierPatch> patches;
    patches.reserve(6);
    for (int n = 0; n < 6; ++n) patches.push_back(sheet(rng, {0, 0, 0}, 2.0f, 0.5f, 0.5f, 2.0f));
    for (int m = 0; m < 516; m += 7) {
        for (int kind = 0; kind < 3; ++kind) {
            std::vector<TableTerm> bad = table;
            if (kind == 0) bad[m].weight = -bad[m].weight;
            if (kind == 1) bad.erase(bad.begin() + m);
            if (kind == 2) bad[m].dest = (bad[m].dest + 9) % 64;
            double worst = 0;
            for (const BezierPatch& p : patches) worst = std::max(worst, max_relative_plane_error(bad, p, rng));
            EXPECT_GT(worst, 1e-6) << "mutation " << kind << " of term " << m << " went unnoticed";
        }
    }
}

// The kernels' schedule (pairs, thirds, signs, corner anchors; ptp_schedule.h) gives the table's
// cross4Z values: evaluated in double, t_z per destination agrees with the table's.
TEST(PtpSchedule, ReproducesTheTableInDouble) {
    using ptp_detail::kSchedule;
    std::mt19937 rng(13);
    const std::vector<TableTerm> table = compiled_table();
    EXPECT_LE(ptp_detail::kPairCount, 70);
    for (int n = 0; n < 50; ++n) {
        const BezierPatch p = sheet(rng, {0, 0, 0}, 2.0f, 0.5f, 0.5f, 2.0f);
        const std::array<D4, 64> ref = control_planes(table, p);
        struct P3 {
            double x, y, w;
        };
        P3 q[16];
        for (int k = 0; k < 16; ++k) q[k] = {p.cp[k].x, p.cp[k].y, p.cp[k].w};
        auto det_pair = [](P3 a, P3 b, P3 c) {
            return c.x * (a.y * b.w - a.w * b.y) - c.y * (a.x * b.w - a.w * b.x) + c.w * (a.x * b.y - a.y * b.x);
        };
        for (int d = 0; d < 64; ++d) {
            double t = 0;
            const int ci = kSchedule.corner_of_dest[d];
            if (ci >= 0) {
                const auto& cr = kSchedule.corners[ci];
                const P3 a = q[cr.a], b = q[cr.b], c = q[cr.c];
                t = cr.weight * det_pair(a, {b.x - a.x, b.y - a.y, b.w - a.w}, {c.x - a.x, c.y - a.y, c.w - a.w});
            } else {
                for (int s = kSchedule.dest_first[d]; s < kSchedule.dest_first[d + 1]; ++s) {
                    const auto& st = kSchedule.steps[s];
                    t +=
                        st.weight * det_pair(q[kSchedule.pairs[st.pair].a], q[kSchedule.pairs[st.pair].b], q[st.third]);
                }
            }
            // cross4's z component is det[[x],[y],[w]]: what the kernels compute in clip space.
            EXPECT_NEAR(t, ref[d].z, 1e-5 * (1 + std::fabs(ref[d].z))) << "dest " << d;
        }
    }
}

// The scalar kernel's float control planes (the arithmetic both kernels share, since their
// decisions agree bit for bit, test (d)) against the table evaluated in double from the same
// clip-space rows: every coefficient within a few float roundings of the magnitude of its terms
// (sum over its terms of |weight| |a| |b| |c|, the error scale of a float 3x3 determinant).
// Sensitive to any error in the schedule (a flipped, dropped or misplaced term is off by about
// its own magnitude), which decision tests alone would catch only rarely. Collapsed edges give
// exact zeros on their 8 boundary control planes.
TEST(PtpKernel, ControlPlanesMatchDoublePrecision) {
    std::mt19937 rng(14);
    std::uniform_real_distribution<float> u(-1, 1);
    double worst = 0;
    for (int n = 0; n < 2000; ++n) {
        BezierPatch p = random_patch(rng, 3.0f);
        const int collapsed = n % 3 == 0 ? n % 4 : -1;
        if (collapsed >= 0) p = collapse_edge(p, collapsed);
        const View view = make_view({10 * u(rng), 10 * u(rng), 10 * u(rng)}, {u(rng), u(rng), u(rng)},
                                    n % 2 ? model_matrix(rng, n % 4 == 1) : Mat4{});
        ptp_detail::PtpClipRows rows;
        ASSERT_TRUE(ptp_detail::ptp_clip_rows(view.object_to_clip, view.alpha, rows));
        float t[64];
        ptp_detail::ptp_control_planes_z(p, rows, t);
        double q[16][3];
        for (int k = 0; k < 16; ++k)
            for (int r = 0; r < 3; ++r)
                q[k][r] = rows.r[r][0] * double(p.cp[k].x) + rows.r[r][1] * double(p.cp[k].y) +
                          rows.r[r][2] * double(p.cp[k].z) + rows.r[r][3] * double(p.cp[k].w);
        double ref[64] = {}, mag[64] = {};
        for (const TableTerm& r : compiled_table()) {
            const double* a = q[r.j];
            const double* b = q[r.k];
            const double* c = q[r.l];
            const double v = r.weight * det3(a[0], b[0], c[0], a[1], b[1], c[1], a[2], b[2], c[2]);
            ref[r.dest] += v;
            // Error scale of a float 3x3 determinant: the product of its columns' lengths.
            auto len = [](const double* x) { return std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]); };
            mag[r.dest] += std::fabs(r.weight) * len(a) * len(b) * len(c);
        }
        for (int d = 0; d < 64; ++d) {
            const double err = std::fabs(t[d] - ref[d]) / (mag[d] > 0 ? mag[d] : 1.0);
            worst = std::max(worst, err);
            ASSERT_LE(err, 2e-6) << "patch " << n << " dest " << d << ": " << t[d] << " vs " << ref[d];
        }
        if (collapsed >= 0)
            for (int k = 0; k < 8; ++k) {
                const int d = collapsed == 0 ? k : collapsed == 1 ? 8 * k + 7 : collapsed == 2 ? 56 + k : 8 * k;
                EXPECT_EQ(t[d], 0.0f) << "patch " << n << " collapsed edge " << collapsed << " dest " << d;
            }
    }
    RecordProperty("worst_relative_error", std::to_string(worst));
}

// The rounding-error margin (ptp_schedule.h) bounds the float kernel's error against the exact
// control planes of the same float inputs, where it matters most: small patches far from the eye
// (clip-space extent E down to 1e-5 of the magnitude R), nearly flat or curved, polynomial or
// rational, with model matrices (mirroring ones included) and collapsed edges (margin 0 there,
// exact zeros). The reference is the table in double, on clip points computed in double from the
// same float rows and control points (cancellation there costs ~2^-50 R^3, far below the margin).
// The largest error / margin ratio is recorded (about 1/100: the margin is a worst-case bound,
// the observed errors add up like a random walk) and must be above 1/1000: a margin a thousand
// times smaller would be violated, so the check has teeth.
TEST(PtpKernel, RoundingMarginBoundsTheError) {
    std::mt19937 rng(15);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    const std::vector<TableTerm> table = compiled_table();
    double worst_ratio = 0;
    int zero_margins = 0;
    for (int n = 0; n < (kSlowBuild ? 600 : 6000); ++n) {
        const float distance = std::pow(10.0f, 3.0f * unit(rng));
        const float size = distance * std::pow(10.0f, -5.0f + 5.0f * unit(rng));
        const float bump = n % 3 == 0 ? 0.0f : std::pow(10.0f, -4.0f + 3.0f * unit(rng));
        const Vec3 dir = normalize(Vec3{u(rng), u(rng), u(rng)});
        BezierPatch p = sheet(rng, dir * distance, size, bump, n % 5 == 0 ? 0.5f : 1.0f, n % 5 == 0 ? 2.0f : 1.0f);
        if (n % 7 == 0) p = collapse_edge(p, n % 4);
        const Vec3 eye = Vec3{u(rng), u(rng), u(rng)} * (0.1f * distance);
        const View view = make_view(eye, dir * distance, n % 2 ? model_matrix(rng, n % 4 == 1) : Mat4{});
        ptp_detail::PtpClipRows rows;
        ASSERT_TRUE(ptp_detail::ptp_clip_rows(view.object_to_clip, view.alpha, rows));
        float t[64], thr[64];
        ptp_detail::ptp_control_planes_z(p, rows, t);
        ASSERT_TRUE(ptp_detail::ptp_rounding_margins(p, rows, thr));
        double q[16][3];
        for (int k = 0; k < 16; ++k)
            for (int r = 0; r < 3; ++r)
                q[k][r] = rows.r[r][0] * double(p.cp[k].x) + rows.r[r][1] * double(p.cp[k].y) +
                          rows.r[r][2] * double(p.cp[k].z) + rows.r[r][3] * double(p.cp[k].w);
        double ref[64] = {};
        for (const TableTerm& r : table) {
            const double* a = q[r.j];
            const double* b = q[r.k];
            const double* c = q[r.l];
            ref[r.dest] += r.weight * det3(a[0], b[0], c[0], a[1], b[1], c[1], a[2], b[2], c[2]);
        }
        for (int d = 0; d < 64; ++d) {
            const double err = std::fabs(double(t[d]) - ref[d]);
            ASSERT_GE(thr[d], 0.0f);
            if (thr[d] == 0) {
                ++zero_margins;
                ASSERT_EQ(t[d], 0.0f) << "patch " << n << " dest " << d << ": margin 0 off a collapsed edge";
                continue;
            }
            ASSERT_LE(err, thr[d]) << "patch " << n << " dest " << d << ": |" << t[d] << " - " << ref[d]
                                   << "| exceeds the margin " << thr[d];
            worst_ratio = std::max(worst_ratio, err / thr[d]);
        }
    }
    RecordProperty("worst_error_to_margin", std::to_string(worst_ratio));
    std::printf("[ ptp margin ] worst error / margin = %.3g, %d zero margins\n", worst_ratio, zero_margins);
    EXPECT_GT(worst_ratio, 0.001);
    EXPECT_GT(zero_margins, 0);
}

// Non-finite coordinates: the kernels keep the patch.
TEST(PtpKernel, NonFiniteControlPointsAreKept) {
    BezierPatch p;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) p.cp[4 * j + i] = homogeneous({i / 3.0f - 0.5f, j / 3.0f - 0.5f, 0.0f});
    const View below = make_view({0.1f, 0.2f, -2.0f}, {0, 0, 0});
    ptp_detail::PtpClipRows rows;
    ASSERT_TRUE(ptp_detail::ptp_clip_rows(below.object_to_clip, below.alpha, rows));
    std::vector<BezierPatch> patches = {p};
    for (float bad : {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                      std::numeric_limits<float>::quiet_NaN()})
        for (int k : {0, 5, 15}) {
            BezierPatch q = p;
            q.cp[k].z = bad;
            patches.push_back(q);
            float thr[64];
            // An infinite coordinate has no margin; a NaN one gives NaN planes (no rule holds).
            if (std::isinf(bad)) {
                EXPECT_FALSE(ptp_detail::ptp_rounding_margins(q, rows, thr)) << "point " << k;
            }
        }
    const PatchBatch batch = make_batch(patches);
    for (Impl impl : {Impl::kScalar, Impl::kSimd})
        for (PtpRule rule : {PtpRule::ncnt, PtpRule::pcnt}) {
            const std::vector<std::uint8_t> c = run_ptp(impl, batch.view(), below, rule);
            EXPECT_EQ(c[0], 1);  // the finite one is back-facing from below
            for (std::size_t i = 1; i < c.size(); ++i) EXPECT_EQ(c[i], 0) << "non-finite patch " << i << " culled";
        }
}

// ---- (c) decisions are conservative ------------------------------------------------------------

namespace {

struct ConservativeStats {
    int culled = 0, checked = 0;
    double worst = -1;
};

// Runs both rules with the scalar kernel and checks each culled patch against dense sampling.
void check_conservative(const std::vector<BezierPatch>& patches, const View& view, ConservativeStats& stats,
                        const char* what) {
    const PatchBatch batch = make_batch(patches);
    const D4 e = object_space_eye(view);
    for (PtpRule rule : {PtpRule::ncnt, PtpRule::pcnt}) {
        const std::vector<std::uint8_t> c = run_ptp(Impl::kScalar, batch.view(), view, rule);
        for (std::size_t i = 0; i < patches.size(); ++i) {
            ++stats.checked;
            if (!c[i]) continue;
            ++stats.culled;
            const double f = max_facing(patches[i], e);
            stats.worst = std::max(stats.worst, f);
            EXPECT_LE(f, kFacingTolerance) << what << ": patch " << i << " culled by "
                                           << (rule == PtpRule::ncnt ? "ncnt" : "pcnt") << " but faces the eye";
        }
    }
}

}  // namespace

TEST(PtpKernel, CullsOnlyBackFacingPatchesRandomViews) {
    std::mt19937 rng(21);
    std::uniform_real_distribution<float> u(-1, 1);
    ConservativeStats stats;
    for (int v = 0; v < 12; ++v) {
        std::vector<BezierPatch> patches;
        patches.reserve(300);
        for (int n = 0; n < 300; ++n) patches.push_back(random_patch(rng, 4.0f));
        const Vec3 eye{12 * u(rng), 12 * u(rng), 12 * u(rng)};
        const Mat4 model = v < 4 ? Mat4{} : model_matrix(rng, v % 2 == 1);  // half of these mirror
        check_conservative(patches, make_view(eye, {0, 0, 0}, model), stats, "random view");
    }
    // The test has teeth: a good share of the random patches is culled.
    EXPECT_GT(stats.culled, stats.checked / 20);
    RecordProperty("worst_facing", std::to_string(stats.worst));
    EXPECT_LE(stats.worst, 1e-6);  // in practice culled patches face away: float noise stays far below the tolerance
}

TEST(PtpKernel, CullsOnlyBackFacingPatchesEyeCloseToTheSurface) {
    std::mt19937 rng(22);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    ConservativeStats stats;
    for (int n = 0; n < 400; ++n) {
        // Planar and slightly curved sheets (an eye this close sees some of any visibly curved one).
        const float bump = n % 4 == 0 ? 0.0f : n % 4 == 1 ? 1e-4f : n % 4 == 2 ? 1e-3f : 1e-2f;
        const Vec3 c{u(rng), u(rng), u(rng)};
        const BezierPatch p = n % 8 < 4 ? sheet(rng, c, 1.0f, bump, 1, 1) : sheet(rng, c, 1.0f, bump, 0.5f, 2.0f);
        // Eye just off a surface point, on either side, at distances from 1e-4 to 1e-1.
        const float su = unit(rng), sv = unit(rng);
        const SurfacePoint sp = evaluate_surface(p, su, sv);
        const Vec3 nrm = normalize(sp.normal);
        if (length(sp.normal) == 0) continue;
        const float dist = std::pow(10.0f, -4.0f + 3.0f * unit(rng)) * (n % 3 ? -1.0f : 1.0f);  // mostly behind
        const Vec3 eye = sp.position + nrm * dist + Vec3{u(rng), u(rng), u(rng)} * (0.1f * std::fabs(dist));
        const Vec3 target = sp.position - nrm * (dist > 0 ? 1.0f : -1.0f) + Vec3{0.01f, 0.02f, 0.0f};
        check_conservative({p}, make_view(eye, target), stats, "eye near the surface");
    }
    EXPECT_GT(stats.culled, 100);
}

TEST(PtpKernel, TeapotIsConservativeAndPcntCullsTheDegenerateTop) {
    const std::vector<BezierPatch> teapot = teapot_patches();
    ConservativeStats stats;
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int v = 0; v < (kSlowBuild ? 6 : 40); ++v) {
        const Vec3 eye = normalize(Vec3{u(rng), u(rng), u(rng)}) * (4.0f + 6.0f * std::fabs(u(rng)));
        check_conservative(teapot, make_view(eye, {0, 0, 1.5f}), stats, "teapot");
    }
    EXPECT_GT(stats.culled, 0);
    // The knob (20-23) and the bottom (28-31) collapse their v = 0 edge to a point, so their
    // v = 0 control planes are exactly zero: Ncnt (all < 0) can never cull them, Pcnt (none > 0)
    // can. The knob is a mushroom (its underside faces down), so a knob quarter is back-facing
    // only from the opposite side, level with or below it; the bottom from above.
    const PatchBatch batch = make_batch(teapot);
    std::array<int, 32> pcnt_only{};
    for (int el = -10; el <= 60; el += 10)
        for (int az = 0; az < 360; az += 15) {
            if (kSlowBuild && ((el > 0 && el != 40) || az % 30 != 0)) continue;
            const double e = el * kPi / 180, a = az * kPi / 180;
            const Vec3 eye{static_cast<float>(6 * std::cos(e) * std::cos(a)),
                           static_cast<float>(6 * std::cos(e) * std::sin(a)),
                           static_cast<float>(1.5 + 6 * std::sin(e))};
            const View view = make_view(eye, {0, 0, 1.5f});
            if (!kSlowBuild || az % 90 == 0) check_conservative(teapot, view, stats, "teapot ring");
            for (Impl impl : {Impl::kScalar, Impl::kSimd}) {
                const std::vector<std::uint8_t> ncnt = run_ptp(impl, batch.view(), view, PtpRule::ncnt);
                const std::vector<std::uint8_t> pcnt = run_ptp(impl, batch.view(), view, PtpRule::pcnt);
                for (int k : {20, 21, 22, 23, 28, 29, 30, 31}) {
                    EXPECT_EQ(ncnt[k], 0) << "degenerate patch " << k << " culled by ncnt";
                    if (impl == Impl::kScalar) pcnt_only[k] += pcnt[k];
                }
            }
        }
    for (int k : {20, 21, 22, 23}) EXPECT_GE(pcnt_only[k], 1) << "knob patch " << k << " never culled by pcnt";
    for (int k : {28, 29, 30, 31})
        EXPECT_GE(pcnt_only[k], kSlowBuild ? 1 : 50) << "bottom patch " << k << " rarely culled by pcnt";
    // Knob quarter 20 (u from +x towards -y) from the opposite side, level with the teapot's middle.
    const View opposite = make_view({-3.0f, 5.2f, 1.5f}, {0, 0, 1.5f});
    EXPECT_EQ(run_ptp(Impl::kSimd, batch.view(), opposite, PtpRule::pcnt)[20], 1);
    EXPECT_EQ(run_ptp(Impl::kSimd, batch.view(), opposite, PtpRule::ncnt)[20], 0);
}

TEST(PtpKernel, CollapsedEdgesOfEveryKindArePcntCullable) {
    // A flat, back-facing square with one edge collapsed (a triangle): Pcnt culls it whichever
    // edge collapsed, polynomial or rational; Ncnt does not.
    std::mt19937 rng(24);
    std::vector<BezierPatch> patches;
    for (int e = 0; e < 4; ++e)
        for (float w : {1.0f, 0.0f}) {
            BezierPatch p;
            std::uniform_real_distribution<float> wr(0.5f, 2.0f);
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i)  // z = 0 plane, du x dv = +z
                    p.cp[4 * j + i] = homogeneous({i / 3.0f, j / 3.0f, 0.0f}, w == 1.0f ? 1.0f : wr(rng));
            patches.push_back(collapse_edge(p, e));
        }
    const View below = make_view({0.3f, 0.4f, -3.0f}, {0.3f, 0.4f, 0.0f});
    const PatchBatch batch = make_batch(patches);
    for (Impl impl : {Impl::kScalar, Impl::kSimd}) {
        const std::vector<std::uint8_t> ncnt = run_ptp(impl, batch.view(), below, PtpRule::ncnt);
        const std::vector<std::uint8_t> pcnt = run_ptp(impl, batch.view(), below, PtpRule::pcnt);
        for (std::size_t i = 0; i < patches.size(); ++i) {
            EXPECT_EQ(ncnt[i], 0) << i;
            EXPECT_EQ(pcnt[i], 1) << i;
        }
    }
    // From above the same patches face the eye: nothing culled.
    const View above = make_view({0.3f, 0.4f, 3.0f}, {0.3f, 0.4f, 0.0f});
    const std::vector<std::uint8_t> pcnt = run_ptp(Impl::kSimd, batch.view(), above, PtpRule::pcnt);
    for (std::uint8_t c : pcnt) EXPECT_EQ(c, 0);
}

TEST(PtpKernel, HandBuiltCasesAndOrientation) {
    // A flat square in z = 0 with du x dv = +z: from above it faces the eye, from below it does not.
    BezierPatch p;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) p.cp[4 * j + i] = homogeneous({i / 3.0f - 0.5f, j / 3.0f - 0.5f, 0.0f});
    const PatchBatch batch = make_batch({p});
    std::mt19937 rng(25);
    for (bool mirror : {false, true}) {
        const Mat4 model = model_matrix(rng, mirror);
        Mat4 model_inv;
        ASSERT_TRUE(invert(model, model_inv));
        // Eyes given in object space, mapped to world through the model matrix.
        auto world = [&](Vec3 o) {
            const Vec4 w = model * homogeneous(o);
            return Vec3{w.x, w.y, w.z};
        };
        const View above = make_view(world({0.1f, 0.2f, 2.0f}), world({0, 0, 0}), model);
        const View below = make_view(world({0.1f, 0.2f, -2.0f}), world({0, 0, 0}), model);
        for (Impl impl : {Impl::kScalar, Impl::kSimd})
            for (PtpRule rule : {PtpRule::ncnt, PtpRule::pcnt}) {
                EXPECT_EQ(run_ptp(impl, batch.view(), above, rule)[0], 0) << "mirror " << mirror;
                EXPECT_EQ(run_ptp(impl, batch.view(), below, rule)[0], 1) << "mirror " << mirror;
            }
    }
    // Degenerate view (alpha = 0): nothing is culled.
    const View below = make_view({0.1f, 0.2f, -2.0f}, {0, 0, 0});
    const View none{below.object_to_clip, 0.0f};
    EXPECT_EQ(run_ptp(Impl::kScalar, batch.view(), none, PtpRule::pcnt)[0], 0);
    EXPECT_EQ(run_ptp(Impl::kSimd, batch.view(), none, PtpRule::pcnt)[0], 0);
}

// ---- (d) scalar and SIMD agree ----------------------------------------------------------------

TEST(PtpKernel, ScalarAndSimdDecisionsAreIdentical) {
    std::mt19937 rng(31);
    std::uniform_real_distribution<float> u(-1, 1);
    // Not a multiple of any lane width; >= 100k in Release (the ASan + UBSan Debug build: 12011).
    constexpr std::size_t kCount = kSlowBuild ? 12011 : 100003;
    std::vector<BezierPatch> patches;
    patches.reserve(kCount);
    for (std::size_t n = 0; n < kCount; ++n) patches.push_back(random_patch(rng, 6.0f));
    for (int k = 0; k < 64; ++k) patches[k * 157] = teapot_patches()[k % 32];
    const PatchBatch batch = make_batch(patches);
    std::vector<View> views;
    for (int v = 0; v < 3; ++v) {
        const Vec3 eye{10 * u(rng), 10 * u(rng), 10 * u(rng)};
        views.push_back(make_view(eye, {0, 0, 0}, v == 2 ? model_matrix(rng, true) : Mat4{}));
    }
    std::size_t culled_total = 0, compared = 0;
    for (const View& view : views)
        for (PtpRule rule : {PtpRule::ncnt, PtpRule::pcnt}) {
            if (kSlowBuild && &view != &views[0]) continue;
            const std::vector<std::uint8_t> ref = run_ptp(Impl::kScalar, batch.view(), view, rule);
            for (std::uint8_t c : ref) culled_total += c;
            for_each_simd_target([&](std::int64_t target) {
                // Targets without FMA instructions (SSSE3, SSE4, emulated) do every fma through
                // libm, ~50x slower: they get a 10007-patch prefix.
                const bool fast = target <= HWY_AVX2;  // x86 targets: better = lower bit
                const std::size_t n_all = fast ? kCount : kSlowBuild ? 2003 : 10007;
                const std::vector<std::uint8_t> simd =
                    run_ptp(Impl::kSimd, batch.view().subrange(0, n_all), view, rule);
                std::size_t diff = 0;
                for (std::size_t i = 0; i < n_all; ++i) diff += simd[i] != ref[i];
                EXPECT_EQ(diff, 0u);
                compared += n_all;
                // Subranges at odd offsets and lengths (tails of every size).
                for (std::size_t first : {std::size_t{1}, std::size_t{17}, std::size_t{4099}})
                    for (std::size_t n :
                         {std::size_t{1}, std::size_t{7}, std::size_t{15}, std::size_t{33}, std::size_t{1001}}) {
                        const std::vector<std::uint8_t> sub =
                            run_ptp(Impl::kSimd, batch.view().subrange(first, n), view, rule);
                        for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(sub[i], ref[first + i]) << first << "+" << i;
                    }
            });
        }
    EXPECT_GT(culled_total, (kSlowBuild ? 2 : 6) * kCount / 20);  // decisions of both kinds were compared
    EXPECT_GT(compared, 0u);
}
