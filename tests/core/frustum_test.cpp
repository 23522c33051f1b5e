// View-frustum kernels (patchcull/core/frustum.h): hand-built cases for both kernels, exact agreement of
// every compiled SIMD target with the scalar reference, and conservativeness against dense
// sampling of the displaced surface in double precision.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/frustum.h"
#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

constexpr float kPi = 3.14159265358979f;

enum class Kernel { kFrustum, kFrustumDisp };
enum class Impl { kScalar, kSimd };

const char* kernel_name(Kernel k) { return k == Kernel::kFrustum ? "frustum" : "frustum-disp"; }

// Runs one kernel; the output buffer has guard bytes after count that must stay untouched.
std::vector<std::uint8_t> run_cull(Kernel kernel, Impl impl, const PatchBatchView& view, const float* disp,
                                   const Mat4& object_to_clip) {
    constexpr std::size_t kGuard = 64;
    std::vector<std::uint8_t> out(view.count + kGuard, 0xAB);
    if (kernel == Kernel::kFrustum) {
        const FrustumPlanes planes = make_frustum_planes(object_to_clip, ClipDepth::zero_to_one);
        (impl == Impl::kScalar ? cull_frustum_scalar : cull_frustum_simd)(view, disp, planes, out.data());
    } else {
        (impl == Impl::kScalar ? cull_frustum_disp_scalar : cull_frustum_disp_simd)(view, disp, object_to_clip,
                                                                                    ClipDepth::zero_to_one, out.data());
    }
    for (std::size_t i = view.count; i < out.size(); ++i) EXPECT_EQ(out[i], 0xAB) << "wrote past count at " << i;
    out.resize(view.count);
    return out;
}

// Calls body(is_best) once per SIMD target compiled into the library and supported by this CPU,
// best first (the one normal dispatch picks), with the dispatch forced to that target; restores
// normal dispatch afterwards.
void for_each_simd_target(const std::function<void(bool)>& body) {
    bool best = true;
    for (std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(std::string("SIMD target ") + hwy::TargetName(target));
        EXPECT_STREQ(simd_target_name(), hwy::TargetName(target));
        body(best);
        best = false;
    }
    hwy::SetSupportedTargetsForTest(0);
}

// Flat polynomial patch: bilinear interpolation of four corners (cp[4*j + i] at u = i/3, v = j/3),
// every point with weight w (homogeneous (w*x, w*y, w*z, w)).
BezierPatch bilinear_patch(Vec3 p00, Vec3 p10, Vec3 p01, Vec3 p11, float w = 1.0f) {
    BezierPatch patch;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const float u = i / 3.0f, v = j / 3.0f;
            const Vec3 p = (p00 * (1 - u) + p10 * u) * (1 - v) + (p01 * (1 - u) + p11 * u) * v;
            patch.cp[4 * j + i] = homogeneous(p, w);
        }
    return patch;
}

// Axis-aligned rectangle at depth z (view space), camera at the origin looking down -z.
BezierPatch rect_at(float x0, float x1, float y0, float y1, float z) {
    return bilinear_patch({x0, y0, z}, {x1, y0, z}, {x0, y1, z}, {x1, y1, z});
}

// 90 degree square frustum, camera at the origin looking down -z, near 1, far 100: at depth t the
// visible square is [-t, t]^2.
Mat4 simple_view() { return perspective(0.5f * kPi, 1.0f, 1.0f, 100.0f) * look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}); }

struct Decision {
    bool frustum, frustum_disp;
};

// Both kernels, both implementations, on one patch; fails if scalar and SIMD disagree.
Decision cull_one(const BezierPatch& patch, const Mat4& m, const float* disp = nullptr) {
    const PatchBatch batch = make_batch({patch});
    Decision d{};
    for (Kernel k : {Kernel::kFrustum, Kernel::kFrustumDisp}) {
        const auto s = run_cull(k, Impl::kScalar, batch.view(), disp, m);
        const auto v = run_cull(k, Impl::kSimd, batch.view(), disp, m);
        EXPECT_EQ(s[0], v[0]) << kernel_name(k);
        EXPECT_TRUE(s[0] == 0 || s[0] == 1);
        (k == Kernel::kFrustum ? d.frustum : d.frustum_disp) = s[0] != 0;
    }
    return d;
}

}  // namespace

TEST(FrustumPlanes, ExtractsRowsAsDocumented) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> r(-3, 3);
    Mat4 m;
    for (float& v : m.m) v = r(rng);
    const FrustumPlanes p = make_frustum_planes(m, ClipDepth::zero_to_one);
    auto same = [](Vec4 a, Vec4 b) { return a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w; };
    const Vec4 x = m.row(0), y = m.row(1), z = m.row(2), w = m.row(3);
    EXPECT_TRUE(same(p.rows[0], w + x));
    EXPECT_TRUE(same(p.rows[1], w - x));
    EXPECT_TRUE(same(p.rows[2], w + y));
    EXPECT_TRUE(same(p.rows[3], w - y));
    EXPECT_TRUE(same(p.rows[4], z));
    EXPECT_TRUE(same(p.rows[5], w - z));
    for (int q = 0; q < 6; ++q) EXPECT_FLOAT_EQ(p.normal_length[q], length(xyz(p.rows[q])));
    // A point's plane values are its clip-space inequalities.
    const Vec4 P{0.3f, -0.7f, 1.1f, 1.0f};
    const Vec4 c = m * P;
    const float expect[6] = {c.w + c.x, c.w - c.x, c.w + c.y, c.w - c.y, c.z, c.w - c.z};
    for (int q = 0; q < 6; ++q) EXPECT_NEAR(dot(p.rows[q], P), expect[q], 1e-4f);
}

TEST(FrustumKernels, CullPatchesOutsideOnePlaneAndKeepTheRest) {
    const Mat4 m = simple_view();
    struct Case {
        const char* name;
        BezierPatch patch;
        bool culled;
    };
    const Case cases[] = {
        {"fully left", rect_at(-30, -25, -2, 2, -10), true},
        {"fully right", rect_at(25, 30, -2, 2, -10), true},
        {"fully below", rect_at(-2, 2, -30, -25, -10), true},
        {"fully above", rect_at(-2, 2, 25, 30, -10), true},
        {"between eye and near plane", rect_at(-0.2f, 0.2f, -0.2f, 0.2f, -0.5f), true},
        {"behind the eye", rect_at(-3, 3, -3, 3, 5), true},
        {"beyond far", rect_at(-2, 2, -2, 2, -150), true},
        {"inside", rect_at(-2, 2, -2, 2, -10), false},
        {"straddling left", rect_at(-15, -5, -2, 2, -10), false},
        {"straddling near", bilinear_patch({-0.1f, 0, -0.5f}, {0.1f, 0, -0.5f}, {-0.1f, 0, -2}, {0.1f, 0, -2}), false},
        {"straddling far", bilinear_patch({-1, 0, -90}, {1, 0, -90}, {-1, 0, -110}, {1, 0, -110}), false},
        {"enclosing the view", rect_at(-100, 100, -100, 100, -10), false},
        {"degenerate point inside", rect_at(1, 1, 1, 1, -10), false},
        {"degenerate point outside", rect_at(11, 11, 1, 1, -10), true},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const Decision d = cull_one(c.patch, m);
        EXPECT_EQ(d.frustum, c.culled);
        EXPECT_EQ(d.frustum_disp, c.culled);
    }
}

// A floor-like patch from behind the eye (clip w < 0) to in front of it, right of the view at both
// ends: every control point projects (after dividing by w) right of the screen, so an NDC-box test
// would cull it, but its middle crosses the view. Homogeneous plane tests keep it.
TEST(FrustumKernels, KeepPatchStraddlingTheEyePlaneThatAnNdcTestWouldCull) {
    const Mat4 m = simple_view();
    // Columns i = 0, 1 at (-10, y, 5) behind the eye, columns 2, 3 at (12, y, -10) in front and right
    // of the view; y from -1 to 1. B(1/2, 1/2) = (1, 0, -2.5) is inside the view.
    BezierPatch patch;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const float y = -1 + 2 * j / 3.0f;
            patch.cp[4 * j + i] = i < 2 ? Vec4{-10, y, 5, 1} : Vec4{12, y, -10, 1};
        }

    bool all_right_after_divide = true, some_w_negative = false, some_w_positive = false;
    for (const Vec4& p : patch.cp) {
        const Vec4 c = m * p;
        all_right_after_divide &= c.x / c.w > 1.0f;
        some_w_negative |= c.w < 0;
        some_w_positive |= c.w > 0;
    }
    ASSERT_TRUE(all_right_after_divide && some_w_negative && some_w_positive)
        << "test patch does not straddle as intended";
    const Vec4 mid = m * evaluate_homogeneous(patch, 0.5f, 0.5f);
    ASSERT_TRUE(mid.w > 0 && std::fabs(mid.x) <= mid.w && std::fabs(mid.y) <= mid.w && mid.z >= 0 && mid.z <= mid.w);

    const Decision d = cull_one(patch, m);
    EXPECT_FALSE(d.frustum);
    EXPECT_FALSE(d.frustum_disp);
}

// A patch just outside a plane is kept when max|D| exceeds its distance, culled otherwise; for
// rational patches the margin scales with the weights so the Cartesian geometry decides.
TEST(FrustumKernels, DisplacementMarginKeepsPatchJustOutside) {
    // Clip space = object space: inside is [-1,1] x [-1,1] x [0,1]; the patch lies 0.05 right of x = 1.
    const Mat4 identity;
    for (float w : {1.0f, 3.0f}) {
        SCOPED_TRACE(w);
        const BezierPatch patch =
            bilinear_patch({1.05f, -0.5f, 0.2f}, {1.05f, 0.5f, 0.2f}, {1.05f, -0.5f, 0.8f}, {1.05f, 0.5f, 0.8f}, w);
        const float small = 0.02f, large = 0.1f;
        const Decision none = cull_one(patch, identity);
        const Decision s = cull_one(patch, identity, &small);
        const Decision l = cull_one(patch, identity, &large);
        EXPECT_TRUE(none.frustum && none.frustum_disp);
        EXPECT_TRUE(s.frustum && s.frustum_disp);
        EXPECT_FALSE(l.frustum || l.frustum_disp);
    }
    // Perspective: points (11, y, z), z in [-10.5, -9.5], right of the plane x = -z. The nearest
    // point is 0.5/sqrt(2) = 0.354 away (frustum keeps for D > 0.354); the AABB grown by D reaches
    // the plane for D >= 0.25 (frustum-disp).
    const Mat4 m = simple_view();
    for (float w : {1.0f, 0.5f}) {
        SCOPED_TRACE(w);
        const BezierPatch patch = bilinear_patch({11, -1, -10.5f}, {11, 1, -10.5f}, {11, -1, -9.5f}, {11, 1, -9.5f}, w);
        const float d02 = 0.2f, d03 = 0.3f, d04 = 0.4f;
        const Decision a = cull_one(patch, m, &d02);
        const Decision b = cull_one(patch, m, &d03);
        const Decision c = cull_one(patch, m, &d04);
        EXPECT_TRUE(a.frustum && a.frustum_disp);
        EXPECT_TRUE(b.frustum);
        EXPECT_FALSE(b.frustum_disp);
        EXPECT_FALSE(c.frustum || c.frustum_disp);
    }
}

namespace {

// ---- random scenes --------------------------------------------------------------------------

struct View {
    Mat4 object_to_clip;
    Mat4 clip_to_object;
    Vec3 eye_object;  // camera position in object space
};

View random_view(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-1, 1);
    const Vec3 eye{10 * u(rng), 5 * u(rng), 10 * u(rng)};
    const Vec3 target{3 * u(rng), 3 * u(rng), 3 * u(rng)};
    // Model: non-uniform scale and a translation, so plane normals are not unit length.
    Mat4 model;
    const Vec3 s{1.0f + 0.5f * u(rng), 1.0f + 0.5f * u(rng), 1.0f + 0.5f * u(rng)};
    const Vec3 t{u(rng), u(rng), u(rng)};
    model.at(0, 0) = s.x;
    model.at(1, 1) = s.y;
    model.at(2, 2) = s.z;
    model.at(0, 3) = t.x;
    model.at(1, 3) = t.y;
    model.at(2, 3) = t.z;
    View v;
    const float fovy = (40 + 40 * (u(rng) + 1) / 2) * kPi / 180;
    v.object_to_clip =
        perspective(fovy, 1.0f + 0.8f * (u(rng) + 1) / 2, 0.1f, 60.0f) * look_at(eye, target, {0, 1, 0}) * model;
    EXPECT_TRUE(invert(v.object_to_clip, v.clip_to_object));
    v.eye_object = {(eye.x - t.x) / s.x, (eye.y - t.y) / s.y, (eye.z - t.z) / s.z};
    return v;
}

Vec3 unproject(const View& v, float x_ndc, float y_ndc, float z_ndc) {
    return cartesian(v.clip_to_object * Vec4{x_ndc, y_ndc, z_ndc, 1});
}

enum PatchKind { kGeneral, kRational, kDegenerate, kEyeStraddling, kNearBoundary, kOnBoundary, kKindCount };

struct RandomPatch {
    BezierPatch patch;
    float max_displacement;
};

// A random bicubic patch around the view. kinds: general (anywhere around the frustum), rational
// (weights 0.25..4), degenerate (collapsed to a point or a curve), straddling the eye plane, near a
// face of the frustum, and exactly on a face (zero extent, plane values ~0).
RandomPatch random_patch(std::mt19937& rng, const View& view, PatchKind kind, bool allow_on_boundary = true) {
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    auto rvec = [&] { return Vec3{u(rng), u(rng), u(rng)}; };
    Vec3 center;
    float size = std::exp(std::log(0.01f) + unit(rng) * (std::log(10.0f) - std::log(0.01f)));
    switch (kind) {
        case kEyeStraddling:
            center = view.eye_object + rvec() * 0.5f;
            size = 1 + 4 * unit(rng);
            break;
        case kNearBoundary:
        case kOnBoundary: {
            float ndc[3] = {u(rng), u(rng), unit(rng)};
            const int axis = static_cast<int>(rng() % 3);
            const float side = axis == 2 ? static_cast<float>(rng() % 2) : (rng() % 2 ? 1.0f : -1.0f);
            const float eps = kind == kOnBoundary || !allow_on_boundary ? 0.0f : 0.05f * u(rng);
            ndc[axis] = side + (axis == 2 ? 0.5f : 1.0f) * eps;
            if (axis != 2) ndc[2] = 0.9f + 0.1f * unit(rng);  // most of the depth range is near z = 1
            center = unproject(view, ndc[0], ndc[1], ndc[2]);
            size = kind == kOnBoundary ? 0.0f : 0.001f + 0.5f * unit(rng);
            break;
        }
        default:
            center = unproject(view, 1.6f * u(rng), 1.6f * u(rng), 0.8f + 0.25f * unit(rng));
            break;
    }
    // A curved sheet: two random axes spanning the grid plus a random bump along a third.
    const Vec3 a = rvec() * size, b = rvec() * size, n = rvec() * size;
    const int degenerate_mode = static_cast<int>(rng() % 3);  // a point, a curve in u, a curve in v
    RandomPatch r;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            Vec3 p = center + a * (i / 3.0f - 0.5f) + b * (j / 3.0f - 0.5f) + n * (0.5f * u(rng));
            if (kind == kDegenerate)
                p = degenerate_mode == 0 ? center : center + (degenerate_mode == 1 ? a * (i / 3.0f) : b * (j / 3.0f));
            const float w = kind == kRational ? std::exp(std::log(0.25f) + unit(rng) * std::log(16.0f)) : 1.0f;
            r.patch.cp[4 * j + i] = homogeneous(p, w);
        }
    if (kind == kOnBoundary) {
        for (auto& cp : r.patch.cp) cp = r.patch.cp[0];
    }
    const float dscale = kind == kOnBoundary ? 0.01f : size;
    r.max_displacement = unit(rng) < 0.3f ? 0.0f : dscale * 0.5f * unit(rng);
    return r;
}

struct RandomScene {
    View view;
    std::vector<BezierPatch> patches;
    std::vector<float> disp;
};

RandomScene random_scene(std::mt19937& rng, std::size_t count, bool allow_on_boundary = true) {
    RandomScene s;
    s.view = random_view(rng);
    for (std::size_t i = 0; i < count; ++i) {
        auto kind = static_cast<PatchKind>(rng() % kKindCount);
        if (kind == kOnBoundary && !allow_on_boundary) kind = kNearBoundary;
        const RandomPatch r = random_patch(rng, s.view, kind, allow_on_boundary);
        s.patches.push_back(r.patch);
        s.disp.push_back(r.max_displacement);
    }
    return s;
}

std::size_t count_culled(const std::vector<std::uint8_t>& c) {
    return static_cast<std::size_t>(std::count(c.begin(), c.end(), 1));
}

void expect_same(const std::vector<std::uint8_t>& scalar, const std::vector<std::uint8_t>& simd, const char* what) {
    ASSERT_EQ(scalar.size(), simd.size());
    std::size_t mismatches = 0, first = 0;
    for (std::size_t i = 0; i < scalar.size(); ++i)
        if (scalar[i] != simd[i] && mismatches++ == 0) first = i;
    EXPECT_EQ(mismatches, 0u) << what << ": first mismatch at " << first << " (scalar " << int(scalar[first])
                              << ", simd " << int(simd[first]) << ")";
}

}  // namespace

// 4 views x 30,001 patches (120,004 in all), with and without displacement, on the target that
// dispatch picks on this machine; the other compiled targets (narrower or without FMA: used only on
// older CPUs) on the first 8,001 patches of each view, which keeps the sanitizer run short.
TEST(FrustumSimd, MatchesScalarExactlyOnRandomPatches) {
    constexpr std::size_t kOtherTargetCount = 8001;
    std::mt19937 rng(2024);
    std::size_t total = 0, culled_total[2] = {0, 0};
    for (int scene_index = 0; scene_index < 4; ++scene_index) {
        const RandomScene scene = random_scene(rng, 30001);
        const PatchBatch batch = make_batch(scene.patches);
        total += batch.size();
        for (Kernel k : {Kernel::kFrustum, Kernel::kFrustumDisp}) {
            SCOPED_TRACE(kernel_name(k));
            for (const float* disp : {scene.disp.data(), static_cast<const float*>(nullptr)}) {
                const auto ref = run_cull(k, Impl::kScalar, batch.view(), disp, scene.view.object_to_clip);
                if (disp) culled_total[k == Kernel::kFrustum ? 0 : 1] += count_culled(ref);
                for_each_simd_target([&](bool best) {
                    const std::size_t n = best ? batch.size() : kOtherTargetCount;
                    const auto simd =
                        run_cull(k, Impl::kSimd, batch.view().subrange(0, n), disp, scene.view.object_to_clip);
                    expect_same(std::vector<std::uint8_t>(ref.begin(), ref.begin() + static_cast<std::ptrdiff_t>(n)),
                                simd, disp ? "with displacement" : "without displacement");
                });
            }
        }
    }
    EXPECT_GE(total, 100000u);
    // The scenes exercise both outcomes (a kernel that culls nothing or everything would agree trivially).
    for (std::size_t c : culled_total) {
        EXPECT_GT(c, total / 10);
        EXPECT_LT(c, total * 9 / 10);
    }
}

// Subranges at unaligned offsets, lengths that are not multiples of any lane width, and a range that
// ends exactly at the end of the allocation (under ASan, any load past it would be reported).
TEST(FrustumSimd, MatchesScalarOnUnalignedSubranges) {
    std::mt19937 rng(99);
    const RandomScene scene = random_scene(rng, 4096);  // count == stride: no padding at all
    const PatchBatch batch = make_batch(scene.patches);
    ASSERT_EQ(batch.stride(), batch.size());
    const std::size_t n = batch.size();
    const std::pair<std::size_t, std::size_t> ranges[] = {
        {0, 1},     {1, 1},       {3, 5},     {5, 17},      {7, 33},      {1, 1023},
        {13, 2000}, {n - 21, 21}, {n - 1, 1}, {n - 37, 37}, {17, n - 17}, {100, 0},
    };
    for (Kernel k : {Kernel::kFrustum, Kernel::kFrustumDisp}) {
        SCOPED_TRACE(kernel_name(k));
        for (const auto& [first, len] : ranges) {
            SCOPED_TRACE("subrange " + std::to_string(first) + " + " + std::to_string(len));
            const PatchBatchView sub = batch.view().subrange(first, len);
            const float* disp = scene.disp.data() + first;
            const auto ref = run_cull(k, Impl::kScalar, sub, disp, scene.view.object_to_clip);
            // The subrange's decisions are the full batch's decisions for those patches.
            const auto full = run_cull(k, Impl::kScalar, batch.view(), scene.disp.data(), scene.view.object_to_clip);
            ASSERT_TRUE(std::equal(ref.begin(), ref.end(), full.begin() + static_cast<std::ptrdiff_t>(first)));
            for_each_simd_target([&](bool) {
                expect_same(ref, run_cull(k, Impl::kSimd, sub, disp, scene.view.object_to_clip), "subrange");
            });
        }
    }
}

namespace {

// Ground truth in double: samples of the patch on a 17x17 grid, each moved by max|D| along a set of
// unit directions (the coordinate axes, the cube diagonals and +- every clip plane's normal, which
// is the direction that brings a point closest to that plane's inside), plus the undisplaced sample.
// Returns true if any of those points is inside the clip volume.
bool any_displaced_sample_inside(const BezierPatch& patch, float max_d, const Mat4& m) {
    double M[4][4];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) M[r][c] = m.at(r, c);
    std::vector<std::array<double, 3>> dirs = {{0, 0, 0}};
    for (int a = 0; a < 3; ++a)
        for (double s : {-1.0, 1.0}) {
            std::array<double, 3> d{0, 0, 0};
            d[a] = s;
            dirs.push_back(d);
        }
    const double k = 1 / std::sqrt(3.0);
    for (int i = 0; i < 8; ++i) dirs.push_back({(i & 1 ? k : -k), (i & 2 ? k : -k), (i & 4 ? k : -k)});
    const int sign_row[6][2] = {{1, 0}, {-1, 0}, {1, 1}, {-1, 1}, {0, 2}, {-1, 2}};  // w +- row, or z
    for (const auto& [s, r] : sign_row) {
        double n[3];
        for (int c = 0; c < 3; ++c) n[c] = s == 0 ? M[r][c] : M[3][c] + s * M[r][c];
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len == 0) continue;
        dirs.push_back({n[0] / len, n[1] / len, n[2] / len});
        dirs.push_back({-n[0] / len, -n[1] / len, -n[2] / len});
    }
    auto bernstein = [](double t, double b[4]) {
        const double s = 1 - t;
        b[0] = s * s * s;
        b[1] = 3 * t * s * s;
        b[2] = 3 * t * t * s;
        b[3] = t * t * t;
    };
    constexpr int kGrid = 17;
    for (int iv = 0; iv < kGrid; ++iv)
        for (int iu = 0; iu < kGrid; ++iu) {
            double bu[4], bv[4];
            bernstein(iu / double(kGrid - 1), bu);
            bernstein(iv / double(kGrid - 1), bv);
            double h[4] = {0, 0, 0, 0};
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i) {
                    const Vec4& cp = patch.cp[4 * j + i];
                    const double b = bu[i] * bv[j];
                    h[0] += b * cp.x;
                    h[1] += b * cp.y;
                    h[2] += b * cp.z;
                    h[3] += b * cp.w;
                }
            const double X[3] = {h[0] / h[3], h[1] / h[3], h[2] / h[3]};
            for (const auto& d : dirs) {
                const double P[3] = {X[0] + max_d * d[0], X[1] + max_d * d[1], X[2] + max_d * d[2]};
                double c[4];
                for (int r = 0; r < 4; ++r) c[r] = M[r][0] * P[0] + M[r][1] * P[1] + M[r][2] * P[2] + M[r][3];
                if (c[3] + c[0] >= 0 && c[3] - c[0] >= 0 && c[3] + c[1] >= 0 && c[3] - c[1] >= 0 && c[2] >= 0 &&
                    c[3] - c[2] >= 0)
                    return true;
            }
        }
    return false;
}

}  // namespace

// No culled patch has a displaced sample inside the clip volume. Patches exactly on a face are left
// out here: the kernels evaluate in float and do not pad for rounding (see frustum.cpp).
TEST(FrustumKernels, CulledPatchesHaveNoDisplacedSampleInside) {
    std::mt19937 rng(31337);
    std::size_t checked[2] = {0, 0};
    for (int scene_index = 0; scene_index < 3; ++scene_index) {
        const RandomScene scene = random_scene(rng, 1500, /*allow_on_boundary=*/false);
        const PatchBatch batch = make_batch(scene.patches);
        for (Kernel k : {Kernel::kFrustum, Kernel::kFrustumDisp}) {
            SCOPED_TRACE(kernel_name(k));
            const auto culled = run_cull(k, Impl::kScalar, batch.view(), scene.disp.data(), scene.view.object_to_clip);
            std::size_t false_culls = 0;
            for (std::size_t i = 0; i < culled.size(); ++i) {
                if (!culled[i]) continue;
                ++checked[k == Kernel::kFrustum ? 0 : 1];
                if (any_displaced_sample_inside(scene.patches[i], scene.disp[i], scene.view.object_to_clip)) {
                    if (false_culls++ < 3) ADD_FAILURE() << "patch " << i << " culled but a displaced sample is inside";
                }
            }
            EXPECT_EQ(false_culls, 0u);
        }
    }
    EXPECT_GT(checked[0], 500u);
    EXPECT_GT(checked[1], 500u);
}

TEST(FrustumSimd, ReportsTheDispatchedTarget) {
    const std::string name = simd_target_name();
    EXPECT_FALSE(name.empty());
    bool known = false;
    for (std::int64_t t : hwy::SupportedAndGeneratedTargets()) known |= name == hwy::TargetName(t);
    EXPECT_TRUE(known) << name;
}
