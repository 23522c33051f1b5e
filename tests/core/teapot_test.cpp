// The built-in Utah teapot: data integrity (pinned against the published data set), shared
// boundaries, degenerate patches and outward orientation.
#include "patchcull/core/teapot.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "patchcull/core/patch.h"

namespace patchcull {
namespace {

// Patch ranges in the data set's order (see src/core/teapot.cpp).
constexpr int kRim = 0, kBody = 4, kHandle = 12, kSpout = 16, kKnob = 20, kLid = 24, kBottom = 28;

Vec3 point(const BezierPatch& p, int i, int j) { return cartesian(p.cp[4 * j + i]); }

bool same(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// Control points of one boundary of a patch, in parameter order: edge 0 is v = 0 (j = 0), 1 is
// u = 1 (i = 3), 2 is v = 1 (j = 3), 3 is u = 0 (i = 0).
std::array<Vec3, 4> edge(const BezierPatch& p, int e) {
    std::array<Vec3, 4> r;
    for (int k = 0; k < 4; ++k) {
        switch (e) {
            case 0:
                r[k] = point(p, k, 0);
                break;
            case 1:
                r[k] = point(p, 3, k);
                break;
            case 2:
                r[k] = point(p, k, 3);
                break;
            default:
                r[k] = point(p, 0, k);
                break;
        }
    }
    return r;
}

bool same(const std::array<Vec3, 4>& a, const std::array<Vec3, 4>& b) {
    return same(a[0], b[0]) && same(a[1], b[1]) && same(a[2], b[2]) && same(a[3], b[3]);
}

std::array<Vec3, 4> reversed(std::array<Vec3, 4> a) {
    std::reverse(a.begin(), a.end());
    return a;
}

// (u, v) of parameter t along edge e.
void edge_uv(int e, float t, float& u, float& v) {
    switch (e) {
        case 0:
            u = t, v = 0;
            break;
        case 1:
            u = 1, v = t;
            break;
        case 2:
            u = t, v = 1;
            break;
        default:
            u = 0, v = t;
            break;
    }
}

TEST(Teapot, HasThirtyTwoPolynomialPatches) {
    const std::vector<BezierPatch> patches = teapot_patches();
    ASSERT_EQ(patches.size(), 32u);
    for (const BezierPatch& p : patches)
        for (const Vec4& c : p.cp) {
            EXPECT_EQ(c.w, 1.0f);
            EXPECT_TRUE(is_finite(xyz(c)));
        }
}

TEST(Teapot, ControlPointsMatchThePublishedData) {
    const std::vector<BezierPatch> patches = teapot_patches();
    ASSERT_EQ(patches.size(), 32u);
    // First rim patch, straight from the data set (vertices 1, 4, 13, 16 and 6).
    EXPECT_TRUE(same(point(patches[0], 0, 0), Vec3{1.4f, 0.0f, 2.4f}));
    EXPECT_TRUE(same(point(patches[0], 3, 0), Vec3{0.0f, -1.4f, 2.4f}));
    EXPECT_TRUE(same(point(patches[0], 0, 3), Vec3{1.5f, 0.0f, 2.4f}));
    EXPECT_TRUE(same(point(patches[0], 3, 3), Vec3{0.0f, -1.5f, 2.4f}));
    EXPECT_TRUE(same(point(patches[0], 1, 1), Vec3{1.3375f, -0.749f, 2.53125f}));
    // Spout tip (vertex 189), handle (vertex 136), knob top (204), bottom centre (270).
    EXPECT_TRUE(same(point(patches[18], 3, 1), Vec3{3.525f, 0.0f, 2.49375f}));
    EXPECT_TRUE(same(point(patches[12], 3, 3), Vec3{-3.0f, 0.0f, 1.8f}));
    EXPECT_TRUE(same(point(patches[kKnob], 2, 0), Vec3{0.0f, 0.0f, 3.15f}));
    EXPECT_TRUE(same(point(patches[kBottom], 1, 0), Vec3{0.0f, 0.0f, 0.0f}));

    // Sums over all 512 control-point slots, computed from the published data set (in decimal;
    // the tolerances cover float rounding of the coordinates): a wrong digit or sign in any used
    // vertex moves one of the first three, a wrong or swapped index moves the weighted one.
    double sx = 0, say = 0, sz = 0, weighted = 0;
    for (int p = 0; p < 32; ++p)
        for (int k = 0; k < kPatchPoints; ++k) {
            const Vec3 c = xyz(patches[p].cp[k]);
            sx += c.x;
            say += std::fabs(c.y);
            sz += c.z;
            weighted += (double(c.x) + 2.0 * c.y + 3.0 * c.z) * double(16 * p + k + 1);
        }
    EXPECT_NEAR(sx, 18.9, 1e-4);
    EXPECT_NEAR(say, 312.44, 1e-4);
    EXPECT_NEAR(sz, 883.275, 1e-4);
    EXPECT_NEAR(weighted, 675125.7445, 0.05);
}

TEST(Teapot, BoundsMatchTheKnownExtents) {
    // From the data set: the handle reaches x = -3, the spout tip's control point x = 3.525,
    // the body's widest ring |y| = 2, the bottom z = 0 and the knob top z = 3.15.
    Vec3 lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
    for (const BezierPatch& p : teapot_patches())
        for (const Vec4& c : p.cp) {
            lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
            hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
        }
    EXPECT_EQ(lo.x, -3.0f);
    EXPECT_EQ(hi.x, 3.525f);
    EXPECT_EQ(lo.y, -2.0f);
    EXPECT_EQ(hi.y, 2.0f);
    EXPECT_EQ(lo.z, 0.0f);
    EXPECT_EQ(hi.z, 3.15f);
}

// Each named pair of patches shares a whole boundary curve: the four boundary control points are
// identical (same order or reversed), so the curves coincide exactly, and evaluating both sides
// gives the same points.
TEST(Teapot, NeighbouringPatchesShareTheirBoundariesExactly) {
    const std::vector<BezierPatch> patches = teapot_patches();
    struct Seam {
        int a, ea, b, eb;
    };
    std::vector<Seam> seams;
    // Around each ring of four (rim, upper body, lower body, knob, lid, bottom): patch k's u = 1
    // edge is patch k+1's u = 0 edge; handle and spout segments are rings of two (the y < 0 and
    // y > 0 halves of the tube).
    for (int ring : {kRim, kBody, kBody + 4, kKnob, kLid, kBottom})
        for (int k = 0; k < 4; ++k) seams.push_back({ring + k, 1, ring + (k + 1) % 4, 3});
    for (int ring : {kHandle, kHandle + 2, kSpout, kSpout + 2})
        for (int k = 0; k < 2; ++k) seams.push_back({ring + k, 1, ring + (k + 1) % 2, 3});
    // Down the pot: rim -> upper body -> lower body (v = 1 edge to v = 0 edge), knob -> lid, the
    // handle's and spout's two segments.
    for (int k = 0; k < 4; ++k) {
        seams.push_back({kRim + k, 2, kBody + k, 0});
        seams.push_back({kBody + k, 2, kBody + 4 + k, 0});
        seams.push_back({kKnob + k, 2, kLid + k, 0});
    }
    for (int tube : {kHandle, kSpout})
        for (int k = 0; k < 2; ++k) seams.push_back({tube + k, 2, tube + 2 + k, 0});
    // The lower body's bottom edge (v = 1) is the bottom's outer edge (v = 1), reversed, with the
    // bottom's quadrants in the opposite order (duplicate vertices in the data, same coordinates).
    for (int k = 0; k < 4; ++k) seams.push_back({kBody + 4 + k, 2, kBottom + 3 - k, 2});
    ASSERT_EQ(seams.size(), 52u);

    for (const Seam& s : seams) {
        SCOPED_TRACE(::testing::Message() << "patches " << s.a << " and " << s.b);
        const std::array<Vec3, 4> ca = edge(patches[s.a], s.ea);
        const std::array<Vec3, 4> cb = edge(patches[s.b], s.eb);
        const bool forward = same(ca, cb);
        const bool backward = same(ca, reversed(cb));
        ASSERT_TRUE(forward || backward);
        for (int n = 0; n <= 8; ++n) {
            const float t = n / 8.0f;
            float ua, va, ub, vb;
            edge_uv(s.ea, t, ua, va);
            edge_uv(s.eb, forward ? t : 1.0f - t, ub, vb);
            const Vec3 pa = evaluate_position(patches[s.a], ua, va);
            const Vec3 pb = evaluate_position(patches[s.b], ub, vb);
            EXPECT_LT(length(pa - pb), 1e-5f) << "t = " << t;
        }
    }
}

// Degenerate patches: a whole boundary edge collapses to one point, so du x dv vanishes along it.
// The teapot has exactly eight: the four knob patches (at the knob's top) and the four bottom
// patches (at the bottom's centre), both on the v = 0 edge.
TEST(Teapot, HasEightDegeneratePatches) {
    const std::vector<BezierPatch> patches = teapot_patches();
    std::vector<int> degenerate;
    for (int p = 0; p < 32; ++p) {
        bool collapsed = false;
        for (int e = 0; e < 4; ++e) {
            const std::array<Vec3, 4> c = edge(patches[p], e);
            if (same(c[0], c[1]) && same(c[1], c[2]) && same(c[2], c[3])) collapsed = true;
        }
        if (collapsed) degenerate.push_back(p);
    }
    EXPECT_EQ(degenerate, (std::vector<int>{20, 21, 22, 23, 28, 29, 30, 31}));

    for (int p : degenerate) {
        SCOPED_TRACE(::testing::Message() << "patch " << p);
        const float scale = length(point(patches[p], 3, 3) - point(patches[p], 0, 0));
        for (int n = 0; n <= 4; ++n) {
            const SurfacePoint at_edge = evaluate_surface(patches[p], n / 4.0f, 0.0f);
            // Zero up to float rounding of the Bernstein derivative weights.
            EXPECT_LT(length(at_edge.du), 1e-5f * scale);
            EXPECT_LT(length(at_edge.normal), 1e-5f * scale * scale);
            // ...but only on that edge: just inside, the normal is regular.
            const SurfacePoint inside = evaluate_surface(patches[p], n / 4.0f, 0.25f);
            EXPECT_GT(length(inside.normal), 1e-3f * scale * scale);
        }
        // Both collapsed points lie on the teapot's axis.
        const Vec3 apex = point(patches[p], 0, 0);
        EXPECT_EQ(apex.x, 0.0f);
        EXPECT_EQ(apex.y, 0.0f);
    }
    // Every other patch has a non-zero normal at all four corners and its centre.
    for (int p = 0; p < 32; ++p) {
        if (std::find(degenerate.begin(), degenerate.end(), p) != degenerate.end()) continue;
        for (float u : {0.0f, 0.5f, 1.0f})
            for (float v : {0.0f, 0.5f, 1.0f})
                EXPECT_GT(length(evaluate_surface(patches[p], u, v).normal), 1e-4f) << "patch " << p;
    }
}

// Outward orientation, patch by patch, on a 9x9 grid of interior samples.
// - body, lid, knob and the bottom's inner part: away from the teapot's axis / centre;
// - rim and spout tip (lips that curl over): away from the centre of the curl;
// - handle and spout tubes: away from the tube's centre line (the midpoint of the u = 0 and u = 1
//   boundary curves, which lie in the y = 0 plane);
// - bottom: additionally points down where it is flat.
// Each test counts samples; a flipped patch would score 0 of 81, so requiring every sample pins
// the orientation of each patch separately.
class TeapotOrientation : public ::testing::Test {
protected:
    std::vector<BezierPatch> patches = teapot_patches();

    template <class Reference>
    int outward_samples(int p, Reference reference) const {
        int outward = 0;
        for (int a = 0; a < 9; ++a)
            for (int b = 0; b < 9; ++b) {
                const float u = (a + 0.5f) / 9, v = (b + 0.5f) / 9;
                const SurfacePoint s = evaluate_surface(patches[p], u, v);
                if (dot(s.normal, s.position - reference(u, v, s.position)) > 0) ++outward;
            }
        return outward;
    }
};

TEST_F(TeapotOrientation, BodyPointsAwayFromTheAxis) {
    for (int p = kBody; p < kBody + 8; ++p)
        EXPECT_EQ(outward_samples(p, [](float, float, Vec3 x) { return Vec3{0, 0, x.z}; }), 81) << "patch " << p;
}

TEST_F(TeapotOrientation, LidAndKnobPointAwayFromTheirCentres) {
    // The lid is a low dome: away from a centre below it.
    for (int p = kLid; p < kLid + 4; ++p)
        EXPECT_EQ(outward_samples(p, [](float, float, Vec3) { return Vec3{0, 0, 1.5f}; }), 81) << "patch " << p;
    // The knob is a bulb on the lid's axis around z = 2.9.
    for (int p = kKnob; p < kKnob + 4; ++p)
        EXPECT_EQ(outward_samples(p, [](float, float, Vec3) { return Vec3{0, 0, 2.9f}; }), 81) << "patch " << p;
}

TEST_F(TeapotOrientation, RimPointsAwayFromItsCurl) {
    // The rim's profile arches from radius 1.4 over z ~ 2.5 down to radius 1.5 at z = 2.4: its
    // outside is away from the arch's centre (radius 1.45, z 2.4).
    for (int p = kRim; p < kRim + 4; ++p)
        EXPECT_EQ(outward_samples(p,
                                  [](float, float, Vec3 x) {
                                      const float r = std::hypot(x.x, x.y);
                                      return Vec3{x.x * 1.45f / r, x.y * 1.45f / r, 2.4f};
                                  }),
                  81)
            << "patch " << p;
}

TEST_F(TeapotOrientation, HandleAndSpoutPointAwayFromTheirCentreLines) {
    for (int p : {kHandle, kHandle + 1, kHandle + 2, kHandle + 3, kSpout, kSpout + 1}) {
        const BezierPatch& patch = patches[p];
        EXPECT_EQ(outward_samples(p,
                                  [&](float, float v, Vec3) {
                                      return (evaluate_position(patch, 0, v) + evaluate_position(patch, 1, v)) * 0.5f;
                                  }),
                  81)
            << "patch " << p;
    }
}

TEST_F(TeapotOrientation, SpoutTipPointsAwayFromItsCurl) {
    // The tip's lip curls over from the spout's end (v = 0) and back down inside (v = 1); its
    // outside faces away from the centre of the curl, which sits on the lip's mean ellipse
    // at z = 2.4: halfway between the v = 0 and v = 1 curves at the same u.
    for (int p = kSpout + 2; p < kSpout + 4; ++p) {
        const BezierPatch& patch = patches[p];
        EXPECT_EQ(outward_samples(p,
                                  [&](float u, float, Vec3) {
                                      return (evaluate_position(patch, u, 0) + evaluate_position(patch, u, 1)) * 0.5f;
                                  }),
                  81)
            << "patch " << p;
    }
}

TEST_F(TeapotOrientation, BottomPointsDownAndOut) {
    for (int p = kBottom; p < kBottom + 4; ++p) {
        EXPECT_EQ(outward_samples(p, [](float, float, Vec3) { return Vec3{0, 0, 1.5f}; }), 81) << "patch " << p;
        // Where the bottom is flat (the inner half), the normal points straight down.
        for (int a = 0; a < 9; ++a)
            for (int b = 1; b < 5; ++b) {
                const SurfacePoint s = evaluate_surface(patches[p], (a + 0.5f) / 9, b / 9.0f);
                EXPECT_LT(s.normal.z, -0.9f * length(s.normal)) << "patch " << p;
            }
    }
}

// Across every shared boundary the two sides' normals agree in direction, so the orientation is
// consistent over each connected piece, not just on average.
TEST_F(TeapotOrientation, NormalsAgreeAcrossSharedBoundaries) {
    int checked = 0;
    for (int a = 0; a < 32; ++a)
        for (int b = a + 1; b < 32; ++b)
            for (int ea = 0; ea < 4; ++ea)
                for (int eb = 0; eb < 4; ++eb) {
                    const std::array<Vec3, 4> ca = edge(patches[a], ea);
                    const std::array<Vec3, 4> cb = edge(patches[b], eb);
                    if (same(ca[0], ca[3]) && same(ca[1], ca[2]) && same(ca[0], ca[1])) continue;  // collapsed
                    const bool forward = same(ca, cb);
                    const bool backward = same(ca, reversed(cb));
                    if (!forward && !backward) continue;
                    ++checked;
                    for (int n = 1; n < 8; ++n) {
                        const float t = n / 8.0f;
                        float ua, va, ub, vb;
                        edge_uv(ea, t, ua, va);
                        edge_uv(eb, forward ? t : 1.0f - t, ub, vb);
                        const Vec3 na = normalize(evaluate_surface(patches[a], ua, va).normal);
                        const Vec3 nb = normalize(evaluate_surface(patches[b], ub, vb).normal);
                        EXPECT_GT(dot(na, nb), 0.5f) << "patches " << a << " and " << b << " t = " << t;
                    }
                }
    // The 52 seams of NeighbouringPatchesShareTheirBoundariesExactly, found here by position.
    EXPECT_EQ(checked, 52);
}

}  // namespace
}  // namespace patchcull
