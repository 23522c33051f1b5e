// Displaced-patch bounds (patchcull/core/displaced_bounds.h): hand-built values, names, NaN/inf and
// unsupported views, batch == single, and ground truth: the displaced surface sampled densely
// (33x33 (u,v), displacements d_min, 0, d_max and random values in between, along the true unit
// normal, all in double precision) must lie inside every bound (caf and oobb x full, acon, con),
// and frustum / Hi-Z decisions must never cull a patch with a sample inside the view volume / in
// front of the depth buffer. Deliberately shrunk bounds (half the displacement range, half the
// cone aperture) run through the same checks and must be caught.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/cone_test_patches.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/teapot.h"

using namespace patchcull;
using cone_test::kSanitizerDivisor;
using cone_test::PatchGen;

namespace {

constexpr DisplacedBoundKind kBounds[] = {DisplacedBoundKind::oobb, DisplacedBoundKind::caf};
constexpr NormalConeKind kCones[] = {NormalConeKind::full, NormalConeKind::acon, NormalConeKind::con};

std::string combo_name(DisplacedBoundKind b, NormalConeKind c) {
    return std::string(displaced_bound_name(b)) + "/" + normal_cone_name(c);
}

// ---- double-precision ground truth -------------------------------------------------------------

struct P3 {
    double x = 0, y = 0, z = 0;
};

/// A surface point of a (possibly rational) patch and its unit normal (quotient rule), in double.
/// has_normal is false where B_u x B_v vanishes (collapsed edges): the surface is not displaced there.
struct SurfacePointD {
    P3 p, n;
    bool has_normal = false;
};

SurfacePointD evaluate_exact(const BezierPatch& patch, double u, double v, double size) {
    double bu[4], dbu[4], bv[4], dbv[4];
    cone_test::bernstein3(u, bu, dbu);
    cone_test::bernstein3(v, bv, dbv);
    double h[4] = {0, 0, 0, 0}, hu[4] = {0, 0, 0, 0}, hv[4] = {0, 0, 0, 0};
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const Vec4 c = patch.cp[4 * j + i];
            const double cc[4] = {c.x, c.y, c.z, c.w};
            for (int k = 0; k < 4; ++k) {
                h[k] += bu[i] * bv[j] * cc[k];
                hu[k] += dbu[i] * bv[j] * cc[k];
                hv[k] += bu[i] * dbv[j] * cc[k];
            }
        }
    SurfacePointD s;
    s.p = {h[0] / h[3], h[1] / h[3], h[2] / h[3]};
    const double pu[3] = {(hu[0] - s.p.x * hu[3]) / h[3], (hu[1] - s.p.y * hu[3]) / h[3],
                          (hu[2] - s.p.z * hu[3]) / h[3]};
    const double pv[3] = {(hv[0] - s.p.x * hv[3]) / h[3], (hv[1] - s.p.y * hv[3]) / h[3],
                          (hv[2] - s.p.z * hv[3]) / h[3]};
    const double n[3] = {pu[1] * pv[2] - pu[2] * pv[1], pu[2] * pv[0] - pu[0] * pv[2], pu[0] * pv[1] - pu[1] * pv[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    // Collapsed edges give |n| ~ 1e-16 size^2 of cancellation noise, whose direction means nothing.
    s.has_normal = len > 1e-9 * size * size;
    if (s.has_normal) s.n = {n[0] / len, n[1] / len, n[2] / len};
    return s;
}

double patch_size(const BezierPatch& patch) {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (const Vec4& c : patch.cp) {
        const double p[3] = {c.x / double(c.w), c.y / double(c.w), c.z / double(c.w)};
        for (int i = 0; i < 3; ++i) {
            lo[i] = std::min(lo[i], p[i]);
            hi[i] = std::max(hi[i], p[i]);
        }
    }
    return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-30});
}

/// grid x grid samples of the displaced surface, each at 4 displacements: d_min, 0, d_max and a
/// uniform random value in [d_min, d_max] (one D value per sample: samples are points S = B + D n).
std::vector<P3> displaced_samples(const BezierPatch& patch, DisplacementRange range, int grid, std::mt19937& rng) {
    std::vector<P3> out;
    out.reserve(static_cast<std::size_t>(grid) * grid * 4);
    std::uniform_real_distribution<double> unit(0, 1);
    const double size = patch_size(patch);
    for (int j = 0; j < grid; ++j)
        for (int i = 0; i < grid; ++i) {
            const SurfacePointD s = evaluate_exact(patch, i / double(grid - 1), j / double(grid - 1), size);
            const double ds[4] = {range.d_min, 0.0, range.d_max, range.d_min + (range.d_max - range.d_min) * unit(rng)};
            for (double d : ds) {
                if (!s.has_normal && d != 0.0) continue;
                out.push_back({s.p.x + d * s.n.x, s.p.y + d * s.n.y, s.p.z + d * s.n.z});
            }
        }
    return out;
}

/// A sample in view space (t = -z) with the float pipeline's rounding allowance `slack` (view units).
struct ViewSampleD {
    double x, y, t;
};

struct Checker {
    double V[4][4], P[4][4];
    double slack = 0;  // allowance for the float transform of the kernels, in view-space units

    Checker(const Mat4& object_to_view, const Mat4& projection) {
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) {
                V[r][c] = object_to_view.at(r, c);
                P[r][c] = projection.at(r, c);
            }
    }

    /// slack = 4e-6 (about 64 ulp) of the largest term the kernels' float transform adds up.
    void set_slack(const BezierPatch& patch, DisplacementRange range) {
        double mag = 0;
        for (const Vec4& c : patch.cp)
            for (int r = 0; r < 3; ++r) {
                const double p[3] = {c.x / double(c.w), c.y / double(c.w), c.z / double(c.w)};
                mag = std::max(mag, std::fabs(V[r][0] * p[0]) + std::fabs(V[r][1] * p[1]) + std::fabs(V[r][2] * p[2]) +
                                        std::fabs(V[r][3]));
            }
        double row = 0;
        for (int r = 0; r < 3; ++r)
            row = std::max(row, std::sqrt(V[r][0] * V[r][0] + V[r][1] * V[r][1] + V[r][2] * V[r][2]));
        slack = 4e-6 * (mag + row * std::max(-double(range.d_min), double(range.d_max)));
    }

    ViewSampleD to_view(const P3& p) const {
        const double x = V[0][0] * p.x + V[0][1] * p.y + V[0][2] * p.z + V[0][3];
        const double y = V[1][0] * p.x + V[1][1] * p.y + V[1][2] * p.z + V[1][3];
        const double z = V[2][0] * p.x + V[2][1] * p.y + V[2][2] * p.z + V[2][3];
        return {x, y, -z};
    }
    double ndc_x(const ViewSampleD& s) const { return (P[0][0] * s.x - P[0][2] * s.t) / s.t; }
    double ndc_y(const ViewSampleD& s) const { return (P[1][1] * s.y - P[1][2] * s.t) / s.t; }
    double depth(const ViewSampleD& s) const { return (-P[2][2] * s.t + P[2][3]) / s.t; }
    /// How much the NDC x (y) of s can move when x (y) and t move by slack.
    /// Plus the float rounding of the kernels' last steps (fma(P00, x/t, -P02); fma(-P22, t, P23) / t):
    /// a few ulp of their terms.
    double ndc_x_slack(const ViewSampleD& s) const {
        const double X = std::fabs(s.x / s.t);
        return std::fabs(P[0][0]) * slack * (1 + X) / s.t + 0x1p-21 * (std::fabs(P[0][0]) * X + std::fabs(P[0][2]));
    }
    double ndc_y_slack(const ViewSampleD& s) const {
        const double Y = std::fabs(s.y / s.t);
        return std::fabs(P[1][1]) * slack * (1 + Y) / s.t + 0x1p-21 * (std::fabs(P[1][1]) * Y + std::fabs(P[1][2]));
    }
    double depth_slack(const ViewSampleD& s) const {
        return std::fabs(P[2][3]) * slack / (s.t * s.t) + 0x1p-21 * (std::fabs(P[2][2]) + std::fabs(P[2][3] / s.t));
    }

    /// Inside the view volume by more than the slack (a sample that must keep its patch).
    bool clearly_inside(const ViewSampleD& s) const {
        const double h[4] = {s.x, s.y, -s.t, 1.0};
        double c[4];
        for (int r = 0; r < 4; ++r) c[r] = P[r][0] * h[0] + P[r][1] * h[1] + P[r][2] * h[2] + P[r][3] * h[3];
        const double planes[6] = {c[3] + c[0], c[3] - c[0], c[3] + c[1], c[3] - c[1], c[2], c[3] - c[2]};
        const double grad[6] = {std::fabs(P[0][0]) + 1 + std::fabs(P[0][2]),
                                std::fabs(P[0][0]) + 1 + std::fabs(P[0][2]),
                                std::fabs(P[1][1]) + 1 + std::fabs(P[1][2]),
                                std::fabs(P[1][1]) + 1 + std::fabs(P[1][2]),
                                std::fabs(P[2][2]),
                                std::fabs(P[2][2]) + 1};
        for (int q = 0; q < 6; ++q)
            if (!(planes[q] > grad[q] * slack)) return false;
        return c[3] > slack;
    }

    /// Is the sample inside the bound (within the slack)? Only for projected bounds.
    bool inside_bound(const DisplacedBound& b, const ViewSampleD& s) const {
        if (!(s.t > 0)) return false;  // a projected bound lies at t > 0
        const double nx = ndc_x(s), ny = ndc_y(s), d = depth(s);
        const double ex = ndc_x_slack(s), ey = ndc_y_slack(s), ed = depth_slack(s);
        return nx >= b.ndc_xmin - ex && nx <= b.ndc_xmax + ex && ny >= b.ndc_ymin - ey && ny <= b.ndc_ymax + ey &&
               d >= b.depth_near - ed && d <= b.depth_far + ed;
    }
};

/// Samples near the eye plane (|t| <= slack) cannot be judged against a rectangle.
bool judgeable(const Checker& ck, const ViewSampleD& s) { return std::fabs(s.t) > ck.slack; }

// ---- random inputs --------------------------------------------------------------------------------

DisplacementRange random_range(std::mt19937& rng, double size) {
    std::uniform_real_distribution<double> unit(0, 1);
    auto magnitude = [&] { return size * std::pow(10.0, -3 + 2.7 * unit(rng)); };
    DisplacementRange r;
    const int kind = static_cast<int>(rng() % 8);
    r.d_min = kind == 0 ? 0.0f : -float(magnitude());
    r.d_max = kind == 1 ? 0.0f : float(magnitude());
    if (kind == 2) r = {};  // no displacement
    return r;
}

/// Object-to-view matrices: mostly the camera's rigid view, sometimes with a non-rigid model
/// matrix (scale, shear) in front of it.
Mat4 random_model(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-1, 1);
    Mat4 m;
    m.at(0, 0) = 1.5f + 0.5f * u(rng);
    m.at(1, 1) = 1.0f + 0.5f * u(rng);
    m.at(2, 2) = 0.6f + 0.3f * u(rng);
    m.at(0, 1) = 0.4f * u(rng);
    m.at(1, 2) = 0.4f * u(rng);
    m.at(0, 3) = u(rng);
    return m;
}

Bounds bounds_of(const BezierPatch& patch, float grow) {
    Bounds b;
    b.min = b.max = cartesian(patch.cp[0]);
    for (const Vec4& c : patch.cp) {
        const Vec3 p = cartesian(c);
        b.min = {std::min(b.min.x, p.x), std::min(b.min.y, p.y), std::min(b.min.z, p.z)};
        b.max = {std::max(b.max.x, p.x), std::max(b.max.y, p.y), std::max(b.max.z, p.z)};
    }
    b.min = b.min - Vec3{grow, grow, grow};
    b.max = b.max + Vec3{grow, grow, grow};
    return b;
}

BezierPatch random_patch(PatchGen& gen, std::mt19937& rng) {
    BezierPatch p = gen.any();
    if (rng() % 10 == 0) {  // rational: cones are invalid, the bounds fall back to full
        std::uniform_real_distribution<float> w(0.5f, 2.0f);
        for (Vec4& c : p.cp) c = c * w(rng);
    }
    return p;
}

/// A depth buffer of random screen rectangles (occluders) at depths drawn around `around`, over a
/// far background: any buffer of values in [0,1] is a valid input of the occlusion test.
std::vector<float> random_depth_buffer(std::mt19937& rng, int W, int H, double around_lo, double around_hi) {
    std::uniform_real_distribution<double> unit(0, 1);
    std::vector<float> depth(static_cast<std::size_t>(W) * H, 1.0f);
    const int rects = 2 + static_cast<int>(rng() % 6);
    for (int r = 0; r < rects; ++r) {
        const int x0 = static_cast<int>(rng() % W), y0 = static_cast<int>(rng() % H);
        const int w = 1 + static_cast<int>(rng() % W), h = 1 + static_cast<int>(rng() % H);
        const double z = std::clamp(around_lo + (around_hi - around_lo) * unit(rng), 0.0, 1.0);
        for (int y = y0; y < std::min(H, y0 + h); ++y)
            for (int x = x0; x < std::min(W, x0 + w); ++x) {
                float& d = depth[static_cast<std::size_t>(y) * W + x];
                d = std::min(d, static_cast<float>(z));
            }
    }
    return depth;
}

// ---- the checks -----------------------------------------------------------------------------------

struct Tally {
    std::size_t bounds = 0, projected = 0, samples = 0, outside = 0;  // containment
    std::size_t frustum_culled = 0, occluded = 0;                     // decisions
    std::size_t containment_violations = 0, frustum_violations = 0, occlusion_violations = 0;
    std::string first;
    void note(const std::string& what) {
        if (first.empty()) first = what;
    }
};

/// Containment: a projected bound holds every judgeable sample; an OutsidePlane bound has no sample
/// clearly inside the view volume (nor does any bound the frustum test culls).
void check_bound(const Checker& ck, const DisplacedBound& b, const std::vector<ViewSampleD>& samples, Tally& tally,
                 const std::string& where) {
    ++tally.bounds;
    tally.projected += b.status == kDisplacedBoundProjected;
    const bool culled = displaced_bound_outside_frustum(b);
    tally.frustum_culled += culled;
    bool contained = true, frustum_ok = true;
    for (const ViewSampleD& s : samples) {
        if (b.status == kDisplacedBoundProjected && judgeable(ck, s)) {
            ++tally.samples;
            if (contained && !ck.inside_bound(b, s)) {
                contained = false;
                char text[400];
                std::snprintf(
                    text, sizeof text,
                    ": sample outside the bound: t %.9g, ndc (%.9g, %.9g) depth %.9g (slacks %.3g %.3g %.3g) vs "
                    "rect [%.9g, %.9g] x [%.9g, %.9g], depth [%.9g, %.9g]",
                    s.t, ck.ndc_x(s), ck.ndc_y(s), ck.depth(s), ck.ndc_x_slack(s), ck.ndc_y_slack(s), ck.depth_slack(s),
                    b.ndc_xmin, b.ndc_xmax, b.ndc_ymin, b.ndc_ymax, b.depth_near, b.depth_far);
                tally.note(where + text);
            }
        }
        if (culled && frustum_ok && ck.clearly_inside(s)) {
            frustum_ok = false;
            tally.note(where + ": frustum-culled with a sample inside the view volume");
        }
    }
    tally.containment_violations += !contained;
    tally.frustum_violations += !frustum_ok;
}

/// Occlusion: an occluded patch has no sample in front of the depth buffer (judged at every pixel
/// the sample can fall in given the slack), and no sample at t <= 0.
void check_occlusion(const Checker& ck, std::uint8_t decision, const std::vector<ViewSampleD>& samples,
                     const std::vector<float>& depth, int W, int H, Tally& tally, const std::string& where) {
    if (decision != kHiZOccluded) return;
    ++tally.occluded;
    for (const ViewSampleD& s : samples) {
        if (!(s.t > ck.slack)) {
            if (s.t < -ck.slack) {
                ++tally.occlusion_violations;
                tally.note(where + ": occluded with a sample behind the eye");
                return;
            }
            continue;
        }
        const double wx = (ck.ndc_x(s) + 1) * 0.5 * W, wy = (ck.ndc_y(s) + 1) * 0.5 * H;
        const double ex = ck.ndc_x_slack(s) * 0.5 * W, ey = ck.ndc_y_slack(s) * 0.5 * H;
        const int x0 = static_cast<int>(std::max(0.0, std::floor(wx - ex))),
                  x1 = static_cast<int>(std::min(W - 1.0, std::floor(wx + ex)));
        const int y0 = static_cast<int>(std::max(0.0, std::floor(wy - ey))),
                  y1 = static_cast<int>(std::min(H - 1.0, std::floor(wy + ey)));
        if (x0 > x1 || y0 > y1 || wx + ex < 0 || wy + ey < 0) continue;  // off screen
        float buffer_min = 1.0f;
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                buffer_min = std::min(buffer_min, depth[static_cast<std::size_t>(y) * W + x]);
        if (ck.depth(s) + ck.depth_slack(s) <= buffer_min) {
            ++tally.occlusion_violations;
            tally.note(where + ": occluded but a sample at depth " + std::to_string(ck.depth(s)) +
                       " is in front of the buffer " + std::to_string(buffer_min));
            return;
        }
    }
}

/// How a bound is computed: the real one, or a deliberately shrunk one.
enum class Variant { kReal, kHalfRange, kHalfAperture, kNoDisplacement };

NormalCone half_aperture(NormalCone c) {
    if (!c.valid) return c;
    const double a = std::acos(std::clamp(double(c.cos_angle), -1.0, 1.0)) * 0.5;
    c.cos_angle = float(std::cos(a));
    c.sin_angle = float(std::sin(a));
    return c;
}

DisplacedBound bound_for(Variant v, const BezierPatch& patch, DisplacementRange range, DisplacedBoundKind b,
                         NormalConeKind c, const DisplacedCullView& view) {
    switch (v) {
        case Variant::kReal:
            return compute_displaced_bound(patch, range, b, c, view);
        case Variant::kHalfRange:
            return compute_displaced_bound(patch, {range.d_min * 0.5f, range.d_max * 0.5f}, b, c, view);
        case Variant::kNoDisplacement:
            return compute_displaced_bound(patch, {}, b, c, view);
        case Variant::kHalfAperture:
            return compute_displaced_bound_with_cone(patch, range, half_aperture(displaced_normal_cone(patch, c)), b,
                                                     view);
    }
    return {};
}

/// The property test over random patches, cameras (free and contain views), displacement ranges
/// and Hi-Z buffers, for one variant. One Tally per bound/cone combination.
std::vector<Tally> run_property(Variant variant, int patches, unsigned seed) {
    PatchGen gen(seed);
    std::mt19937 rng(seed * 7 + 1);
    std::vector<Tally> tally(6);
    constexpr int kGrid = 33, kW = 48, kH = 32;
    for (int trial = 0; trial < patches; ++trial) {
        const BezierPatch patch = random_patch(gen, rng);
        const double size = patch_size(patch);
        const DisplacementRange range = random_range(rng, size);
        const std::vector<P3> object_samples = displaced_samples(patch, range, kGrid, rng);
        const float grow = std::max(-range.d_min, range.d_max);
        ViewGenerator views(bounds_of(patch, grow), trial % 2 ? ViewMode::free : ViewMode::contain, seed + trial,
                            1.0f + 0.5f * static_cast<float>(trial % 3));
        for (int cam_index = 0; cam_index < 3; ++cam_index) {
            const Camera cam = views.next();
            const Mat4 object_to_view = rng() % 4 == 0 ? cam.view() * random_model(rng) : cam.view();
            const DisplacedCullView view =
                make_displaced_cull_view(object_to_view, cam.projection(), ClipDepth::zero_to_one);
            EXPECT_TRUE(view.valid);
            Checker ck(object_to_view, cam.projection());
            ck.set_slack(patch, range);
            std::vector<ViewSampleD> samples;
            samples.reserve(object_samples.size());
            double t_lo = 1e300, t_hi = -1e300;
            for (const P3& p : object_samples) {
                samples.push_back(ck.to_view(p));
                if (samples.back().t > 0) {
                    t_lo = std::min(t_lo, ck.depth(samples.back()));
                    t_hi = std::max(t_hi, ck.depth(samples.back()));
                }
            }
            // Occluders around the patch's own depth range: some in front, some behind, some cutting it.
            const double spread = t_hi > t_lo ? t_hi - t_lo : 0.01;
            const std::vector<float> depth = random_depth_buffer(rng, kW, kH, t_lo - spread, t_hi + 0.2 * spread);
            HiZPyramid hiz;
            hiz.build(depth.data(), kW, kH);
            int index = 0;
            for (DisplacedBoundKind b : kBounds)
                for (NormalConeKind c : kCones) {
                    const std::string where =
                        combo_name(b, c) + " trial " + std::to_string(trial) + " camera " + std::to_string(cam_index);
                    const DisplacedBound bound = bound_for(variant, patch, range, b, c, view);
                    check_bound(ck, bound, samples, tally[index], where);
                    check_occlusion(ck, displaced_bound_hiz_decision(bound, hiz), samples, depth, kW, kH, tally[index],
                                    where);
                    ++index;
                }
        }
    }
    return tally;
}

}  // namespace

// ---- hand-built cases ------------------------------------------------------------------------------

TEST(DisplacedBounds, NamesRoundTrip) {
    for (DisplacedBoundKind b : kBounds) {
        DisplacedBoundKind parsed = b == DisplacedBoundKind::caf ? DisplacedBoundKind::oobb : DisplacedBoundKind::caf;
        ASSERT_TRUE(parse_displaced_bound(displaced_bound_name(b), parsed));
        EXPECT_EQ(parsed, b);
    }
    for (NormalConeKind c : kCones) {
        NormalConeKind parsed = c == NormalConeKind::full ? NormalConeKind::con : NormalConeKind::full;
        ASSERT_TRUE(parse_normal_cone(normal_cone_name(c), parsed));
        EXPECT_EQ(parsed, c);
    }
    EXPECT_STREQ(displaced_bound_name(DisplacedBoundKind::oobb), "oobb");
    EXPECT_STREQ(displaced_bound_name(DisplacedBoundKind::caf), "caf");
    EXPECT_STREQ(normal_cone_name(NormalConeKind::full), "full");
    EXPECT_STREQ(normal_cone_name(NormalConeKind::acon), "acon");
    EXPECT_STREQ(normal_cone_name(NormalConeKind::con), "con");
    DisplacedBoundKind b = DisplacedBoundKind::caf;
    NormalConeKind c = NormalConeKind::acon;
    EXPECT_FALSE(parse_displaced_bound("CAF", b));
    EXPECT_FALSE(parse_normal_cone("ncone", c));
    EXPECT_EQ(b, DisplacedBoundKind::caf);
    EXPECT_EQ(c, NormalConeKind::acon);
}

namespace {

/// A flat 2 x 2 square in the plane z = -distance of view space (identity view), facing the eye
/// (du x dv = +z), centred on the view axis.
BezierPatch facing_square(float distance) {
    BezierPatch p;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) p.cp[4 * j + i] = {-1 + 2 * i / 3.0f, -1 + 2 * j / 3.0f, -distance, 1};
    return p;
}

}  // namespace

// A facing flat square at distance 10, displaced in [-0.5, 0.5]: the values follow from the
// header's formulas by hand. full grows the CAF by 0.5 sideways and in depth; the cones of a flat
// patch are (nearly) the plane normal, so acon/con grow it only in depth; the OOBB of a facing
// square is the same box.
TEST(DisplacedBounds, FacingSquareByHand) {
    const Mat4 proj = perspective(1.0f, 1.0f, 0.5f, 50.0f);
    const DisplacedCullView view = make_displaced_cull_view(Mat4{}, proj, ClipDepth::zero_to_one);
    ASSERT_TRUE(view.valid);
    const BezierPatch square = facing_square(10);
    const DisplacementRange range{-0.5f, 0.5f};
    const double f = proj.at(0, 0);  // ndc_x = f x / t here
    auto depth_at = [&](double t) { return -proj.at(2, 2) + proj.at(2, 3) / t; };
    for (DisplacedBoundKind b : kBounds)
        for (NormalConeKind c : kCones) {
            SCOPED_TRACE(combo_name(b, c));
            const DisplacedBound bound = compute_displaced_bound(square, range, b, c, view);
            ASSERT_EQ(bound.status, kDisplacedBoundProjected);
            EXPECT_NEAR(bound.depth_near, depth_at(9.5), 1e-5);
            EXPECT_NEAR(bound.depth_far, depth_at(10.5), 1e-5);
            // Sideways growth: 0.5 for full (both bounds), ~0 for a cone around the normal.
            const double side = c == NormalConeKind::full ? 1.5 : 1.0;
            EXPECT_NEAR(bound.ndc_xmax, f * side / 9.5, 2e-3);
            EXPECT_NEAR(bound.ndc_xmin, -f * side / 9.5, 2e-3);
            EXPECT_NEAR(bound.ndc_ymax, f * side / 9.5, 2e-3);
            EXPECT_NEAR(bound.ndc_ymin, -f * side / 9.5, 2e-3);
        }
    // Without displacement the CAF is the screen box of the control points (Niessner & Loop, "Patch-Based
    // Occlusion Culling for Hardware Tessellation" §4.2: "the same result as non-displaced patches"): corners
    // at x = +-1, t = 10.
    const DisplacedBound flat =
        compute_displaced_bound(square, {}, DisplacedBoundKind::caf, NormalConeKind::acon, view);
    EXPECT_FLOAT_EQ(flat.ndc_xmax, float(f / 10));
    EXPECT_FLOAT_EQ(flat.depth_near, float(depth_at(10)));
}

// One-sided ranges move the front plane only where the displacement goes: a facing square displaced
// only away from the eye (d_max = 0 with du x dv towards the eye) keeps its front at t = 10.
TEST(DisplacedBounds, OneSidedRangeUsesTheCone) {
    const Mat4 proj = perspective(1.0f, 1.0f, 0.5f, 50.0f);
    const DisplacedCullView view = make_displaced_cull_view(Mat4{}, proj, ClipDepth::zero_to_one);
    const BezierPatch square = facing_square(10);
    auto depth_at = [&](double t) { return -proj.at(2, 2) + proj.at(2, 3) / t; };
    for (DisplacedBoundKind b : kBounds) {
        const DisplacedBound inward = compute_displaced_bound(square, {-1.0f, 0.0f}, b, NormalConeKind::con, view);
        EXPECT_NEAR(inward.depth_near, depth_at(10), 1e-5) << displaced_bound_name(b);
        EXPECT_NEAR(inward.depth_far, depth_at(11), 1e-5) << displaced_bound_name(b);
        const DisplacedBound full = compute_displaced_bound(square, {-1.0f, 0.0f}, b, NormalConeKind::full, view);
        EXPECT_NEAR(full.depth_near, depth_at(9), 1e-5) << displaced_bound_name(b);
    }
}

TEST(DisplacedBounds, BehindAndAcrossTheEye) {
    const Mat4 proj = perspective(1.0f, 1.0f, 0.5f, 50.0f);
    const DisplacedCullView view = make_displaced_cull_view(Mat4{}, proj, ClipDepth::zero_to_one);
    HiZPyramid hiz;
    const std::vector<float> zero(64 * 64, 0.0f);  // everything is occluded, if projectable
    hiz.build(zero.data(), 64, 64);
    // Wholly behind the eye: not projectable, culled by the near plane.
    const BezierPatch behind = facing_square(-5);
    // Across the eye plane: from t = -5 to t = 5, in view: never culled, never occluded.
    BezierPatch across;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) across.cp[4 * j + i] = {-1 + 2 * i / 3.0f, 0.3f, -5 + 10 * j / 3.0f, 1};
    for (DisplacedBoundKind b : kBounds)
        for (NormalConeKind c : kCones) {
            SCOPED_TRACE(combo_name(b, c));
            const DisplacedBound back = compute_displaced_bound(behind, {-0.1f, 0.1f}, b, c, view);
            EXPECT_EQ(back.status, kDisplacedBoundOutsidePlane);
            EXPECT_TRUE(displaced_bound_outside_frustum(back));
            EXPECT_EQ(displaced_bound_hiz_decision(back, hiz), kHiZFrustumCulled);
            const DisplacedBound cross = compute_displaced_bound(across, {-0.1f, 0.1f}, b, c, view);
            EXPECT_EQ(cross.status, kDisplacedBoundUnprojectable);
            EXPECT_FALSE(displaced_bound_outside_frustum(cross));
            EXPECT_EQ(displaced_bound_hiz_decision(cross, hiz), kHiZVisible);
            // In front and projectable: occluded by the all-zero buffer.
            const DisplacedBound front = compute_displaced_bound(facing_square(10), {-0.1f, 0.1f}, b, c, view);
            EXPECT_EQ(displaced_bound_hiz_decision(front, hiz), kHiZOccluded);
        }
}

TEST(DisplacedBounds, NonFiniteInputsAndUnsupportedViewsAreNeverCulled) {
    const Mat4 proj = perspective(1.0f, 1.0f, 0.5f, 50.0f);
    const DisplacedCullView view = make_displaced_cull_view(Mat4{}, proj, ClipDepth::zero_to_one);
    HiZPyramid hiz;
    const std::vector<float> zero(16 * 16, 0.0f);
    hiz.build(zero.data(), 16, 16);
    const BezierPatch behind = facing_square(-5);  // would be culled
    const BezierPatch front = facing_square(10);   // would be occluded
    const float bad_values[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                                -std::numeric_limits<float>::infinity()};
    for (DisplacedBoundKind b : kBounds)
        for (NormalConeKind c : kCones)
            for (float bad : bad_values) {
                SCOPED_TRACE(combo_name(b, c) + " value " + std::to_string(bad));
                for (const BezierPatch& good : {behind, front}) {
                    BezierPatch p = good;
                    p.cp[6].y = bad;
                    DisplacedBound bound = compute_displaced_bound(p, {-0.1f, 0.1f}, b, c, view);
                    EXPECT_EQ(bound.status, kDisplacedBoundInvalid);
                    EXPECT_EQ(displaced_bound_hiz_decision(bound, hiz), kHiZVisible);
                    bound = compute_displaced_bound(good, {bad, 0.1f}, b, c, view);
                    EXPECT_EQ(bound.status, kDisplacedBoundInvalid);
                    EXPECT_EQ(displaced_bound_hiz_decision(bound, hiz), kHiZVisible);
                    bound = compute_displaced_bound(good, {-0.1f, bad}, b, c, view);
                    EXPECT_EQ(displaced_bound_hiz_decision(bound, hiz), kHiZVisible);
                }
                Mat4 bad_view;
                bad_view.at(1, 3) = bad;
                EXPECT_FALSE(make_displaced_cull_view(bad_view, proj, ClipDepth::zero_to_one).valid);
            }
    // Zero or negative weights, and 16 huge coordinates whose sums overflow: never culled.
    for (DisplacedBoundKind b : kBounds) {
        BezierPatch p = behind;
        p.cp[3].w = 0.0f;
        EXPECT_EQ(compute_displaced_bound(p, {}, b, NormalConeKind::full, view).status, kDisplacedBoundInvalid);
        p.cp[3].w = -1.0f;
        EXPECT_EQ(compute_displaced_bound(p, {}, b, NormalConeKind::full, view).status, kDisplacedBoundInvalid);
        // Finite control points whose view coordinates overflow (x 3e38 scaled by 10): inf in the bound.
        BezierPatch huge = facing_square(2);
        for (Vec4& cp : huge.cp) cp.x = cp.x * 3e38f;
        Mat4 scale10;
        scale10.at(0, 0) = scale10.at(1, 1) = scale10.at(2, 2) = 10.0f;
        const DisplacedCullView scaled = make_displaced_cull_view(scale10, proj, ClipDepth::zero_to_one);
        ASSERT_EQ(displaced_bound_hiz_decision(
                      compute_displaced_bound(facing_square(2), {}, b, NormalConeKind::acon, scaled), hiz),
                  kHiZOccluded);
        const DisplacedBound overflow = compute_displaced_bound(huge, {}, b, NormalConeKind::acon, scaled);
        EXPECT_EQ(overflow.status, kDisplacedBoundInvalid);
        EXPECT_EQ(displaced_bound_hiz_decision(overflow, hiz), kHiZVisible);
    }
    // Unsupported projections (orthographic, a translated frustum) and a singular view: nothing is culled.
    Mat4 ortho;
    ortho.at(2, 2) = -0.02f;
    ortho.at(2, 3) = -0.01f;
    Mat4 shifted = proj;
    shifted.at(0, 3) = 0.5f;
    Mat4 singular;
    singular.at(1, 0) = singular.at(1, 1) = singular.at(1, 2) = 0.0f;
    for (const DisplacedCullView& v : {make_displaced_cull_view(Mat4{}, ortho, ClipDepth::zero_to_one),
                                       make_displaced_cull_view(Mat4{}, shifted, ClipDepth::zero_to_one),
                                       make_displaced_cull_view(singular, proj, ClipDepth::zero_to_one)}) {
        EXPECT_FALSE(v.valid);
        for (DisplacedBoundKind b : kBounds) {
            const DisplacedBound bound = compute_displaced_bound(behind, {}, b, NormalConeKind::full, v);
            EXPECT_EQ(bound.status, kDisplacedBoundInvalid);
            EXPECT_EQ(displaced_bound_hiz_decision(bound, hiz), kHiZVisible);
        }
    }
}

// Rational patches have no cone (cones.h): acon and con give exactly the full bound.
TEST(DisplacedBounds, RationalPatchesFallBackToFull) {
    PatchGen gen(5);
    std::mt19937 rng(5);
    const Camera cam;  // at (0,0,5) looking at the origin
    const DisplacedCullView view = make_displaced_cull_view(cam.view(), cam.projection(), ClipDepth::zero_to_one);
    for (int trial = 0; trial < 50; ++trial) {
        BezierPatch p = gen.sheet(0.05);
        std::uniform_real_distribution<float> w(0.5f, 2.0f);
        for (Vec4& c : p.cp) c = c * w(rng);
        for (DisplacedBoundKind b : kBounds) {
            const DisplacedBound full = compute_displaced_bound(p, {-0.1f, 0.05f}, b, NormalConeKind::full, view);
            for (NormalConeKind c : {NormalConeKind::acon, NormalConeKind::con}) {
                const DisplacedBound other = compute_displaced_bound(p, {-0.1f, 0.05f}, b, c, view);
                EXPECT_EQ(other.status, full.status);
                EXPECT_EQ(other.ndc_xmin, full.ndc_xmin);
                EXPECT_EQ(other.ndc_ymax, full.ndc_ymax);
                EXPECT_EQ(other.depth_near, full.depth_near);
            }
        }
    }
}

// The cone only ever shrinks the CAF: ext(acon), ext(con) <= ext(full) axis by axis, and every step of
// the CAF is monotone under inclusion of the boxes, so the CAF with a cone lies inside the full CAF
// for every patch (a theorem, checked bit-for-bit). (Not so for the OOBB, whose frame differs.)
TEST(DisplacedBounds, CafWithAConeLiesInsideTheFullCaf) {
    PatchGen gen(17);
    std::mt19937 rng(17);
    int compared = 0, tighter = 0;
    for (int trial = 0; trial < 2000 / kSanitizerDivisor; ++trial) {
        const BezierPatch p = gen.any();
        const double size = patch_size(p);
        const DisplacementRange range = random_range(rng, size);
        ViewGenerator views(bounds_of(p, float(size)), trial % 2 ? ViewMode::free : ViewMode::contain, trial);
        const Camera cam = views.next();
        const DisplacedCullView view = make_displaced_cull_view(cam.view(), cam.projection(), ClipDepth::zero_to_one);
        const DisplacedBound full =
            compute_displaced_bound(p, range, DisplacedBoundKind::caf, NormalConeKind::full, view);
        for (NormalConeKind c : {NormalConeKind::acon, NormalConeKind::con}) {
            const DisplacedBound b = compute_displaced_bound(p, range, DisplacedBoundKind::caf, c, view);
            if (full.status == kDisplacedBoundProjected) {
                ASSERT_EQ(b.status, kDisplacedBoundProjected) << trial;
                ++compared;
                EXPECT_GE(b.ndc_xmin, full.ndc_xmin) << trial;
                EXPECT_LE(b.ndc_xmax, full.ndc_xmax) << trial;
                EXPECT_GE(b.ndc_ymin, full.ndc_ymin) << trial;
                EXPECT_LE(b.ndc_ymax, full.ndc_ymax) << trial;
                EXPECT_GE(b.depth_near, full.depth_near) << trial;
                EXPECT_LE(b.depth_far, full.depth_far) << trial;
                tighter += b.ndc_xmax - b.ndc_xmin < full.ndc_xmax - full.ndc_xmin;
            }
            if (displaced_bound_outside_frustum(full)) {
                EXPECT_TRUE(displaced_bound_outside_frustum(b)) << trial;
            }
        }
    }
    EXPECT_GT(compared, 1000 / kSanitizerDivisor);
    EXPECT_GT(tighter, compared / 4) << "the cones should usually narrow the rectangle";
}

// The batch kernels make the single-patch decisions, for subranges at odd offsets, with null ranges,
// and write nothing past count.
TEST(DisplacedBounds, BatchMatchesSinglePatch) {
    PatchGen gen(23);
    std::mt19937 rng(23);
    std::vector<BezierPatch> patches;
    std::vector<DisplacementRange> ranges;
    for (int i = 0; i < 300; ++i) {
        BezierPatch p = gen.any();
        // Spread patches around the camera so that every outcome occurs.
        std::uniform_real_distribution<float> u(-1, 1);
        const Vec3 shift{40 * u(rng), 40 * u(rng), 40 * u(rng)};
        const Vec3 c = cartesian(p.cp[0]);
        for (Vec4& cp : p.cp) cp = homogeneous(cartesian(cp) - c + shift, cp.w);
        patches.push_back(p);
        ranges.push_back(random_range(rng, patch_size(p)));
    }
    const PatchBatch batch = make_batch(patches);
    Camera cam;
    cam.eye = {3, 2, 30};
    const DisplacedCullView view = make_displaced_cull_view(cam.view(), cam.projection(), ClipDepth::zero_to_one);
    const std::vector<float> depth = random_depth_buffer(rng, 40, 30, 0.9, 1.0);
    HiZPyramid hiz;
    hiz.build(depth.data(), 40, 30);
    for (DisplacedBoundKind b : kBounds)
        for (NormalConeKind c : kCones) {
            SCOPED_TRACE(combo_name(b, c));
            for (const auto& [first, n] : {std::pair<std::size_t, std::size_t>{0, 300}, {7, 101}, {13, 0}}) {
                const PatchBatchView v = batch.view().subrange(first, n);
                std::vector<std::uint8_t> culled(n + 8, 0xAB), decision(n + 8, 0xAB);
                std::vector<DisplacedBound> bounds(n + 1);
                bounds[n].status = 0xAB;
                cull_displaced_frustum(v, ranges.data() + first, b, c, view, culled.data());
                cull_displaced_occlusion(v, ranges.data() + first, b, c, view, hiz, decision.data());
                compute_displaced_bounds(v, ranges.data() + first, b, c, view, bounds.data());
                EXPECT_EQ(bounds[n].status, 0xAB);
                for (std::size_t k = n; k < n + 8; ++k) {
                    EXPECT_EQ(culled[k], 0xAB);
                    EXPECT_EQ(decision[k], 0xAB);
                }
                for (std::size_t i = 0; i < n; ++i) {
                    const DisplacedBound one =
                        compute_displaced_bound(patches[first + i], ranges[first + i], b, c, view);
                    EXPECT_EQ(culled[i], displaced_bound_outside_frustum(one) ? 1 : 0);
                    EXPECT_EQ(decision[i], displaced_bound_hiz_decision(one, hiz));
                    EXPECT_EQ(bounds[i].status, one.status);
                    EXPECT_EQ(bounds[i].ndc_xmin, one.ndc_xmin);
                    EXPECT_EQ(bounds[i].depth_near, one.depth_near);
                }
            }
            // Null ranges: the undisplaced patches.
            std::vector<std::uint8_t> culled(300);
            cull_displaced_frustum(batch.view(), nullptr, b, c, view, culled.data());
            for (std::size_t i = 0; i < 300; ++i)
                EXPECT_EQ(culled[i],
                          displaced_bound_outside_frustum(compute_displaced_bound(patches[i], {}, b, c, view)) ? 1 : 0);
        }
}

// ---- ground truth --------------------------------------------------------------------------------

// Every sample of every random displaced patch lies in every bound; frustum-culled and occluded
// patches have no sample in the view volume / in front of the depth buffer.
TEST(DisplacedBoundsTruth, EverySampleInsideEveryBound) {
    const std::vector<Tally> tally = run_property(Variant::kReal, 1000 / kSanitizerDivisor, 101);
    int index = 0;
    for (DisplacedBoundKind b : kBounds)
        for (NormalConeKind c : kCones) {
            const Tally& t = tally[index++];
            SCOPED_TRACE(combo_name(b, c));
            EXPECT_EQ(t.containment_violations, 0u) << t.first;
            EXPECT_EQ(t.frustum_violations, 0u) << t.first;
            EXPECT_EQ(t.occlusion_violations, 0u) << t.first;
            // The random inputs exercise every outcome.
            EXPECT_GT(t.projected, t.bounds / 3);
            EXPECT_LT(t.projected, t.bounds);
            EXPECT_GT(t.frustum_culled, 0u);
            EXPECT_GT(t.occluded, 0u);
            EXPECT_GT(t.samples, 100000u / kSanitizerDivisor);
            std::printf(
                "[ displaced truth ] %-9s bounds %zu, projected %zu, samples %zu, frustum-culled %zu, "
                "occluded %zu\n",
                combo_name(b, c).c_str(), t.bounds, t.projected, t.samples, t.frustum_culled, t.occluded);
        }
}

// The same checks catch deliberately shrunk bounds, so the property test can fail:
// - half the displacement range: samples leave every one of the six bounds;
// - half the cone aperture: samples leave the CAF with either cone (the OOBB's corners usually
//   cover that loss, so it is only reported there);
// - no displacement at all (the classic bug): the frustum and Hi-Z decisions cull patches whose
//   displaced samples are visible.
TEST(DisplacedBoundsTruth, ShrunkBoundsAreCaught) {
    const int divisor = std::min(kSanitizerDivisor, 2);
    const std::vector<Tally> half_range = run_property(Variant::kHalfRange, 300 / divisor, 202);
    const std::vector<Tally> half_cone = run_property(Variant::kHalfAperture, 600 / divisor, 303);
    const std::vector<Tally> no_disp = run_property(Variant::kNoDisplacement, 300 / divisor, 404);
    std::size_t decision_violations = 0;
    int index = 0;
    for (DisplacedBoundKind b : kBounds)
        for (NormalConeKind c : kCones) {
            SCOPED_TRACE(combo_name(b, c));
            const Tally& r = half_range[index];
            const Tally& a = half_cone[index];
            const Tally& z = no_disp[index];
            ++index;
            EXPECT_GT(r.containment_violations, r.bounds / 50)
                << "half the displacement range must leave samples outside";
            if (b == DisplacedBoundKind::caf && c != NormalConeKind::full) {
                EXPECT_GT(a.containment_violations, 0u) << "half the cone aperture must leave samples outside";
            }
            decision_violations += z.frustum_violations + z.occlusion_violations;
            std::printf(
                "[ displaced shrunk ] %-9s half range: %zu containment, %zu frustum, %zu occlusion violations "
                "of %zu; half aperture: %zu containment; no displacement: %zu frustum, %zu occlusion\n",
                combo_name(b, c).c_str(), r.containment_violations, r.frustum_violations, r.occlusion_violations,
                r.bounds, a.containment_violations, z.frustum_violations, z.occlusion_violations);
        }
    EXPECT_GT(decision_violations, 0u) << "ignoring the displacement must produce false frustum or Hi-Z culls";
}

// The teapot (degenerate lid and bottom patches kept) under a procedural displacement map, sampled by
// ground_truth.h's sampler along its own (float) normals: every sample in every bound. Cull rates over
// free views and a wall in front of half the screen are printed; in aggregate the cones cull at least
// as much as full.
TEST(DisplacedBoundsTruth, TeapotWithADisplacementMap) {
    const std::vector<BezierPatch> teapot = teapot_patches();
    const DisplacementMap map = make_procedural_displacement(64, 0.3f, 11);
    const Vec2 uv[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    Bounds box{{-3.5f, -2.5f, 0}, {3.5f, 2.5f, 3.2f}};
    ViewGenerator views(box, ViewMode::free, 9);
    constexpr int kGrid = 17, kW = 64, kH = 64;
    std::size_t frustum[6] = {}, occluded[6] = {}, violations = 0, checked = 0;
    std::string first;
    for (int v = 0; v < 60 / kSanitizerDivisor; ++v) {
        const Camera cam = views.next();
        const DisplacedCullView view = make_displaced_cull_view(cam.view(), cam.projection(), ClipDepth::zero_to_one);
        Checker ck(cam.view(), cam.projection());
        // A wall over the left half of the screen at the depth of the box centre.
        std::vector<float> depth(kW * kH, 1.0f);
        const ViewSampleD centre = ck.to_view({0, 0, 1.6});
        const float wall = centre.t > 0 ? static_cast<float>(std::clamp(ck.depth(centre), 0.0, 1.0)) : 1.0f;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW / 2; ++x) depth[y * kW + x] = wall;
        HiZPyramid hiz;
        hiz.build(depth.data(), kW, kH);
        for (const BezierPatch& patch : teapot) {
            const DisplacementRange range = map.patch_range(uv);
            Vec3 pts[kGrid * kGrid];
            sample_displaced_patch(patch, nullptr, uv, &map, kGrid, pts);
            ck.set_slack(patch, range);
            std::vector<ViewSampleD> samples;
            for (const Vec3& p : pts) samples.push_back(ck.to_view({p.x, p.y, p.z}));
            int index = 0;
            for (DisplacedBoundKind b : kBounds)
                for (NormalConeKind c : kCones) {
                    const DisplacedBound bound = compute_displaced_bound(patch, range, b, c, view);
                    Tally t;
                    check_bound(ck, bound, samples, t, combo_name(b, c));
                    const std::uint8_t d = displaced_bound_hiz_decision(bound, hiz);
                    check_occlusion(ck, d, samples, depth, kW, kH, t, combo_name(b, c));
                    violations += t.containment_violations + t.frustum_violations + t.occlusion_violations;
                    if (first.empty()) first = t.first;
                    checked += t.samples;
                    frustum[index] += d == kHiZFrustumCulled;
                    occluded[index] += d == kHiZOccluded;
                    ++index;
                }
        }
    }
    EXPECT_EQ(violations, 0u) << first;
    EXPECT_GT(checked, 10000u / kSanitizerDivisor);
    for (int i = 0; i < 6; ++i)
        std::printf("[ teapot displaced ] %-9s frustum-culled %zu, occluded %zu\n",
                    combo_name(kBounds[i / 3], kCones[i % 3]).c_str(), frustum[i], occluded[i]);
    for (int b = 0; b < 2; ++b)
        for (int c = 1; c < 3; ++c) {
            EXPECT_GE(frustum[3 * b + c] + occluded[3 * b + c], frustum[3 * b] + occluded[3 * b])
                << combo_name(kBounds[b], kCones[c]) << " culls less than full";
        }
}
