// The GPU frustum pass (FrustumPass, shaders/frustum.comp.glsl) against the CPU reference kernel
// cull_frustum_scalar, and the strict id-buffer test: with GPU frustum culling on, the patch-id
// buffer is identical to the unculled render's at the same resolution and tessellation level.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/frustum.h"
#include "patchcull/gl/gl_verification.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

// Random patches in and around a random frustum: clusters of control points near the eye, across
// the planes, behind the eye (w <= 0 in clip space), far beyond; a third rational (weights in
// [0.25, 4]); half the configurations with random displacement margins.
struct RandomCase {
    std::vector<BezierPatch> patches;
    std::vector<float> displacement;  // empty or one per patch
    Mat4 object_to_clip;
};

RandomCase random_case(std::uint32_t seed, std::size_t count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    auto range = [&](float lo, float hi) { return lo + (hi - lo) * u01(rng); };
    Camera cam;
    cam.eye = {range(-3, 3), range(-3, 3), range(-3, 3)};
    cam.target = {range(-1, 1), range(-1, 1), range(-1, 1)};
    cam.up = normalize(Vec3{range(-1, 1), range(-1, 1), range(-1, 1)});
    cam.fovy_radians = range(0.3f, 2.0f);
    cam.aspect = range(0.5f, 2.0f);
    cam.z_near = range(0.01f, 1.0f);
    cam.z_far = cam.z_near + range(0.5f, 20.0f);
    RandomCase c;
    c.object_to_clip = cam.view_projection();
    const bool displaced = seed % 2 == 1;
    for (std::size_t p = 0; p < count; ++p) {
        const Vec3 centre{range(-6, 6), range(-6, 6), range(-6, 6)};
        const float size = std::pow(10.0f, range(-2.0f, 0.5f));
        const bool rational = p % 3 == 0;
        BezierPatch patch;
        for (Vec4& cp : patch.cp) {
            const Vec3 x = centre + Vec3{range(-size, size), range(-size, size), range(-size, size)};
            cp = homogeneous(x, rational ? std::pow(2.0f, range(-2, 2)) : 1.0f);
        }
        c.patches.push_back(patch);
        if (displaced) c.displacement.push_back(u01(rng) < 0.3f ? 0.0f : std::pow(10.0f, range(-3.0f, 0.0f)));
    }
    return c;
}

// cull_frustum_scalar's arithmetic (frustum_plane_values / add_frustum_margins, frustum.h),
// returning the per-plane maxima the decision compares with 0: what the GPU pass reports through
// plane_values.
std::vector<float> cpu_plane_values(const std::vector<BezierPatch>& patches, const float* disp,
                                    const FrustumPlanes& planes) {
    std::vector<float> out(6 * patches.size(), -std::numeric_limits<float>::infinity());
    for (std::size_t p = 0; p < patches.size(); ++p) {
        for (const Vec4& P : patches[p].cp) {
            float v[6];
            frustum_plane_values(planes, P.x, P.y, P.z, P.w, v);
            if (disp) add_frustum_margins(planes, disp[p], P.w, v);
            for (int q = 0; q < 6; ++q) out[6 * p + q] = out[6 * p + q] > v[q] ? out[6 * p + q] : v[q];
        }
    }
    return out;
}

// cull_frustum_scalar's decisions for a case (its margins, when it has them) under planes.
std::vector<std::uint8_t> cpu_frustum_decisions(const RandomCase& c, const FrustumPlanes& planes) {
    const PatchBatch batch = test::unchecked_batch(c.patches);
    std::vector<std::uint8_t> cpu(c.patches.size());
    cull_frustum_scalar(batch.view(), c.displacement.empty() ? nullptr : c.displacement.data(), planes, cpu.data());
    return cpu;
}

std::uint32_t bits(float f) {
    std::uint32_t b;
    std::memcpy(&b, &f, 4);
    return b;
}

}  // namespace

TEST(GpuFrustumCull, SameDecisionsAsCpuKernelOnRandomInputs) {
    PatchRenderer r(test::context());
    std::size_t culled_total = 0, total = 0, value_mismatches = 0;
    for (std::uint32_t seed = 1; seed <= 24; ++seed) {
        const RandomCase c = random_case(seed, 3000);
        PatchAttributes attributes;
        attributes.max_displacement = c.displacement;
        r.set_patches(c.patches, attributes);
        const FrustumPlanes planes = make_frustum_planes(c.object_to_clip, ClipDepth::zero_to_one);
        // Without plane values the pass stops at the point that settles a patch's verdict.
        test::cull_frustum(r, planes);
        const std::vector<std::uint32_t> gpu_stopping = r.read_cull_flags();
        std::vector<float> gpu_values;
        test::cull_frustum(r, planes, &gpu_values);
        const std::vector<std::uint32_t> gpu = r.read_cull_flags();
        ASSERT_EQ(gpu_stopping, gpu) << "seed " << seed;

        const std::vector<std::uint8_t> cpu = cpu_frustum_decisions(c, planes);
        ASSERT_EQ(gpu.size(), cpu.size());
        for (std::size_t p = 0; p < cpu.size(); ++p) {
            ASSERT_EQ(gpu[p] != 0, cpu[p] != 0) << "seed " << seed << " patch " << p;
            if (gpu[p]) {
                ASSERT_EQ(gpu[p], 1u);  // kCullFrustum
            }
            culled_total += cpu[p];
        }
        total += cpu.size();
        // The arithmetic itself: the maxima are bit-identical to the CPU's (fma where it uses fma).
        const std::vector<float> cpu_values =
            cpu_plane_values(c.patches, c.displacement.empty() ? nullptr : c.displacement.data(), planes);
        ASSERT_EQ(gpu_values.size(), cpu_values.size());
        for (std::size_t i = 0; i < cpu_values.size(); ++i) {
            if (bits(gpu_values[i]) != bits(cpu_values[i])) {
                if (value_mismatches < 5)
                    ADD_FAILURE() << "seed " << seed << " patch " << i / 6 << " plane " << i % 6 << ": GPU "
                                  << gpu_values[i] << " CPU " << cpu_values[i];
                ++value_mismatches;
            }
        }
    }
    EXPECT_EQ(value_mismatches, 0u);
    // Both outcomes are well represented.
    EXPECT_GT(culled_total, total / 10);
    EXPECT_LT(culled_total, total * 9 / 10);
}

// The early stop (frustum_test.h: a patch's loop over its points ends once its verdict cannot
// change) keeps the CPU kernel's verdicts where a later point's value could turn a plane's maximum
// back: a NaN or infinite coordinate after inside points, coordinates that overflow the clip
// values to infinity, infinite, NaN and overflowing margins, and matrices with infinite or NaN
// entries (next to zeros: 0 * inf is NaN in one row only).
TEST(GpuFrustumCull, EarlyStopKeepsTheVerdictOnNonFiniteAndOverflowingInput) {
    PatchRenderer r(test::context());
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    const float specials[] = {inf, -inf, nan, 3e38f, -3e38f, 1e20f, 0.0f};
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> pick(0, 6), point(0, 15), coord(0, 3);
    std::size_t compared = 0;
    for (int m = 0; m < 6; ++m) {
        RandomCase c = random_case(100 + static_cast<std::uint32_t>(m), 2000);
        if (c.displacement.empty()) c.displacement.assign(c.patches.size(), 0.01f);
        if (m >= 3) {  // a matrix with one special entry (the rest as the camera made it)
            const float v = m == 3 ? inf : m == 4 ? nan : -inf;
            c.object_to_clip.at(m % 4, (m + 1) % 4) = v;
        }
        // Coordinate i of v set to x; a weight stays positive (the renderer refuses others) but
        // may be huge, infinite or NaN.
        auto set = [](Vec4& v, int i, float x) {
            if (i == 3) {
                v.w = x == 0.0f ? 1e20f : std::fabs(x);
            } else {
                (i == 0 ? v.x : i == 1 ? v.y : v.z) = x;
            }
        };
        for (std::size_t p = 0; p < c.patches.size(); ++p) {
            BezierPatch& patch = c.patches[p];
            switch (p % 5) {
                case 0:  // one special coordinate at a late point
                    set(patch.cp[8 + point(rng) / 2], coord(rng), specials[pick(rng)]);
                    break;
                case 1:  // huge coordinates: clip values overflow
                    for (int k = 4; k < 16; k += 3) set(patch.cp[k], coord(rng), specials[3 + pick(rng) % 3]);
                    break;
                case 2:  // a special margin
                    c.displacement[p] = specials[pick(rng)];
                    break;
                default:
                    break;
            }
        }
        PatchAttributes attributes;
        attributes.max_displacement = c.displacement;
        r.set_patches(c.patches, attributes);
        const FrustumPlanes planes = make_frustum_planes(c.object_to_clip, ClipDepth::zero_to_one);
        test::cull_frustum(r, planes);
        const std::vector<std::uint32_t> gpu = r.read_cull_flags();
        const std::vector<std::uint8_t> cpu = cpu_frustum_decisions(c, planes);
        ASSERT_EQ(gpu.size(), cpu.size());
        for (std::size_t p = 0; p < cpu.size(); ++p)
            ASSERT_EQ(gpu[p] != 0, cpu[p] != 0) << "matrix case " << m << " patch " << p << " (kind " << p % 5 << ")";
        compared += cpu.size();
    }
    EXPECT_EQ(compared, 6u * 2000u);

    // Built to turn a settled maximum back: with an infinite x-row entry for y, a point with y > 0
    // and one with y < 0 give planes 0 and 1 the maxima +inf (every other plane is met), then y = 0
    // gives both NaN (0 * inf), and the points after it, y > 0 again, leave plane 1 at -inf: the
    // CPU culls the patch (its near values are finite), and so must the pass.
    Mat4 skewed;  // identity, clip z = z, clip w = w
    skewed.at(0, 1) = inf;
    BezierPatch turned;
    for (int k = 0; k < 16; ++k) turned.cp[k] = {0.1f, k == 1 ? -0.5f : k == 2 ? 0.0f : 0.5f, 0.5f, 1.0f};
    const std::vector<BezierPatch> one{turned};
    r.set_patches(one, PatchAttributes{});
    const FrustumPlanes skewed_planes = make_frustum_planes(skewed, ClipDepth::zero_to_one);
    test::cull_frustum(r, skewed_planes);
    std::uint8_t cpu_turned = 0;
    cull_frustum_scalar(test::unchecked_batch(one).view(), nullptr, skewed_planes, &cpu_turned);
    EXPECT_EQ(cpu_turned, 1);
    EXPECT_EQ(r.read_cull_flags().at(0) != 0, cpu_turned != 0);
}

TEST(GpuFrustumCull, MultiplyAddIsRoundedOnceOnHardCases) {
    // Clip rows built by hand (not from a matrix) so that the near plane's value (the clip z) for a
    // patch whose 16 points are all (C, 0, 0, B) is exactly fma(A, B, C): z row (1, 0, 0, A), no
    // margin. With A = 2^-24 (1 + 2^-23), B = 1 - 2^-23, C = 1 + 2^-23, A*B + C lies 2^-70 below the
    // midpoint between C and its upper neighbour: the once-rounded result is C; rounding twice
    // (through float or double) ties to the even neighbour 1 + 2^-22. Variants: mirrored signs,
    // powers of two (one pass per A), and random triples; the other planes' values are checked
    // against the CPU's bit for bit as well.
    const float A = std::ldexp(1.0f + std::ldexp(1.0f, -23), -24);
    const float B = 1.0f - std::ldexp(1.0f, -23);
    const float C = 1.0f + std::ldexp(1.0f, -23);
    ASSERT_EQ(std::fma(A, B, C), C);
    ASSERT_NE(static_cast<float>(static_cast<double>(A) * B + C), C);  // the double-rounding trap
    const float a_values[6] = {A, -A, 2 * A, A / 2, -2 * A, 0.75f};
    std::vector<std::pair<float, float>> bc;  // (B, C) per patch
    for (int k = -20; k <= 20; k += 4) {
        bc.push_back({std::ldexp(B, k), std::ldexp(C, k)});
        bc.push_back({std::ldexp(B, k), -std::ldexp(C, k)});
        bc.push_back({-std::ldexp(B, k), -std::ldexp(C, k)});
    }
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f);
    for (int i = 0; i < 2000; ++i) bc.push_back({u(rng), u(rng)});
    // The multiplicand is the patch's weight, which must be positive (patch.h): fma(a, -b, -c) is
    // -fma(a, b, c), rounded alike, so a pair with b <= 0 is negated (b = 0 becomes 2^-20).
    for (auto& [b, c] : bc) {
        if (b < 0) b = -b, c = -c;
        if (b == 0) b = 0x1p-20f;
    }
    std::vector<BezierPatch> patches(bc.size());
    for (std::size_t p = 0; p < bc.size(); ++p)
        for (Vec4& cp : patches[p].cp) cp = {bc[p].second, 0, 0, bc[p].first};

    PatchRenderer r(test::context());
    r.set_patches(patches);
    std::size_t wrong = 0;
    for (const float a : a_values) {
        FrustumPlanes planes;
        planes.clip_rows[0] = {1, 0, 0, -a};
        planes.clip_rows[1] = {0.5f, 0, 0, a};
        planes.clip_rows[2] = {1, 0, 0, a};
        planes.clip_rows[3] = {1, 0, 0, 2 * a};
        for (float& n : planes.normal_length) n = 0;
        std::vector<float> values;
        test::cull_frustum(r, planes, &values);
        ASSERT_EQ(values.size(), 6 * patches.size());
        const std::vector<float> cpu_values = cpu_plane_values(patches, nullptr, planes);
        for (std::size_t p = 0; p < patches.size(); ++p) {
            const float expected = std::fma(a, bc[p].first, bc[p].second);
            if (bits(values[6 * p + 4]) != bits(expected) && ++wrong <= 5)
                ADD_FAILURE() << "fma(" << a << ", " << bc[p].first << ", " << bc[p].second << "): GPU "
                              << values[6 * p + 4] << " expected " << expected;
            for (int q = 0; q < 6; ++q)
                if (bits(values[6 * p + q]) != bits(cpu_values[6 * p + q]) && ++wrong <= 5)
                    ADD_FAILURE() << "plane " << q << " patch " << p << ": GPU " << values[6 * p + q] << " CPU "
                                  << cpu_values[6 * p + q];
        }
        const auto flags = r.read_cull_flags();
        std::vector<std::uint8_t> cpu(patches.size());
        cull_frustum_scalar(make_batch(patches).view(), nullptr, planes, cpu.data());
        for (std::size_t p = 0; p < patches.size(); ++p) ASSERT_EQ(flags[p] != 0, cpu[p] != 0) << "patch " << p;
    }
    EXPECT_EQ(wrong, 0u) << (test::passes().fma_via_double() ? "double-precision emulation" : "native GLSL fma");
}

TEST(GpuFrustumCull, MarginIsUsedAndBeginClearsStaleReasons) {
    // A patch just outside the left plane: culled without margin, kept with a margin larger than
    // its distance.
    Camera cam;  // at (0,0,5) looking at the origin
    const Mat4 vp = cam.view_projection();
    BezierPatch patch;
    for (int k = 0; k < 16; ++k) {
        const int col = k % 4, row = k / 4;
        patch.cp[k] = homogeneous(Vec3{-5.0f - 0.1f * col, 0.1f * row, 0.0f});
    }
    PatchRenderer r(test::context());
    r.set_patches({patch, patch}, test::margins_only({0.0f, 10.0f}));
    const std::uint8_t stale[2] = {0, 1};
    r.set_cull_flags(stale);
    test::cull_frustum(r, make_frustum_planes(vp, ClipDepth::zero_to_one));
    const auto flags = r.read_cull_flags();
    EXPECT_EQ(flags[0], 1u);
    EXPECT_EQ(flags[1], 0u);
}

namespace {

struct StrictStats {
    std::size_t views = 0, culled = 0, visible = 0, false_culls = 0;
    std::size_t cpu_gpu_disagreements = 0;
    std::size_t culled_without_margin_but_visible = 0;  // displaced case only: the margin mattered
};

// For each view: reference render (flags ignored), GPU frustum pass, culled render. The id buffers
// must be identical; every patch present in the reference must be unculled; CPU and GPU decisions
// must agree.
void strict_views(PatchRenderer& r, const std::vector<BezierPatch>& patches, const PatchAttributes& attributes,
                  ViewMode mode, std::uint64_t seed, int views, StrictStats& stats) {
    const PatchBatch batch = test::unchecked_batch(patches);
    const float* disp = attributes.max_displacement.empty() ? nullptr : attributes.max_displacement.data();
    ViewGenerator gen(test::control_point_bounds(patches), mode, seed);
    for (int v = 0; v < views; ++v) {
        const Camera cam = gen.next();
        SCOPED_TRACE(std::string(view_mode_name(mode)) + " view " + std::to_string(v));
        RenderParams params;
        params.view = cam.view();
        params.projection = cam.projection();
        params.width = params.height = 256;
        params.tess_level = 8;
        params.use_cull_flags = false;
        r.render(params);
        const std::vector<std::uint32_t> reference = r.read_ids();

        const FrustumPlanes planes = make_frustum_planes(cam.view_projection(), ClipDepth::zero_to_one);
        test::cull_frustum(r, planes);
        const std::vector<std::uint32_t> flags = r.read_cull_flags();
        params.use_cull_flags = true;
        r.render(params);
        const std::vector<std::uint32_t> culled_ids = r.read_ids();

        std::vector<std::uint8_t> cpu(patches.size());
        cull_frustum_scalar(batch.view(), disp, planes, cpu.data());
        std::vector<std::uint8_t> cpu_no_margin(patches.size());
        if (disp) cull_frustum_scalar(batch.view(), nullptr, planes, cpu_no_margin.data());

        for (std::size_t p = 0; p < patches.size(); ++p)
            stats.cpu_gpu_disagreements += (flags[p] != 0) != (cpu[p] != 0);
        const auto present = test::ids_present(reference);
        for (std::uint32_t id : present) {
            if (flags[id - 1] != 0) {
                ++stats.false_culls;
                ADD_FAILURE() << "false cull: patch " << id - 1 << " is visible unculled but culled";
            }
            if (disp && cpu_no_margin[id - 1]) ++stats.culled_without_margin_but_visible;
        }
        if (culled_ids != reference) {
            std::size_t differ = 0;
            for (std::size_t i = 0; i < reference.size(); ++i) differ += culled_ids[i] != reference[i];
            ADD_FAILURE() << differ << " pixels differ between the culled and the unculled id buffer";
            write_ids_png(::testing::TempDir() + "/patchcull_strict_reference.png", reference, 256, 256);
            write_ids_png(::testing::TempDir() + "/patchcull_strict_culled.png", culled_ids, 256, 256);
        }
        for (auto f : flags) stats.culled += f != 0;
        stats.visible += present.size();
        ++stats.views;
    }
}

}  // namespace

TEST(GpuFrustumCull, StrictIdBufferUnchangedByCulling) {
    const std::vector<BezierPatch> patches = test::split_teapot(2);  // 512 patches
    PatchRenderer r(test::context());
    r.set_patches(patches);
    StrictStats free_stats, contain_stats;
    strict_views(r, patches, {}, ViewMode::free, 11, 24, free_stats);
    strict_views(r, patches, {}, ViewMode::contain, 12, 12, contain_stats);
    EXPECT_EQ(free_stats.false_culls + contain_stats.false_culls, 0u);
    EXPECT_EQ(free_stats.cpu_gpu_disagreements + contain_stats.cpu_gpu_disagreements, 0u);
    // Not vacuous: free views cull many patches and still see many.
    EXPECT_GT(free_stats.culled, free_stats.views * patches.size() / 5);
    EXPECT_GT(free_stats.visible, free_stats.views * 20);
    EXPECT_GT(contain_stats.visible, contain_stats.views * 100);
    RecordProperty("free_culled", static_cast<int>(free_stats.culled));
    RecordProperty("free_visible", static_cast<int>(free_stats.visible));
    RecordProperty("contain_culled", static_cast<int>(contain_stats.culled));
}

TEST(GpuFrustumCull, StrictIdBufferUnchangedByCullingDisplaced) {
    // The rendered surface is displaced (procedural map, each patch sampling its own texture
    // window); the margin is the per-patch DisplacementRange bound. Culling with the margin must not
    // change the id buffer; without the margin some visible patches would be culled (checked, so the
    // case exercises the margin).
    const std::vector<BezierPatch> patches = test::split_teapot(2);
    const Bounds bounds = test::control_point_bounds(patches);
    const DisplacementMap map = make_procedural_displacement(64, 0.08f * length(bounds.max - bounds.min));
    const PatchAttributes attributes = test::random_texture_windows(patches.size(), map, 5);
    PatchRenderer r(test::context());
    r.set_patches(patches, attributes);
    r.set_displacement_map(map);
    StrictStats stats;
    strict_views(r, patches, attributes, ViewMode::free, 21, 24, stats);
    EXPECT_EQ(stats.false_culls, 0u);
    EXPECT_EQ(stats.cpu_gpu_disagreements, 0u);
    EXPECT_GT(stats.culled, stats.views * patches.size() / 10);
    EXPECT_GT(stats.culled_without_margin_but_visible, 0u);
    RecordProperty("culled", static_cast<int>(stats.culled));
    RecordProperty("needed_margin", static_cast<int>(stats.culled_without_margin_but_visible));
}
