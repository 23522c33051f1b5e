// Back-patch cull kernels tcone and ncone (patchcull/core/backpatch.h): conservative against dense
// sampling of e . T = n . (e - p) in double precision (random patches, the teapot, eyes far away,
// just outside the bounding sphere and close to the surface), identical decisions of the scalar
// reference and every compiled SIMD target (random patches, rational ones, NaN, eyes placed on the
// decision boundary, odd counts, subranges), and agreement with the public cone functions.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/cone_test_patches.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/cones.h"
#include "patchcull/core/frustum.h"  // simd_target_name
#include "patchcull/core/ground_truth.h"
#include "patchcull/core/teapot.h"

using namespace patchcull;
using namespace patchcull::cone_test;

namespace {

constexpr double kPi = 3.14159265358979323846;

enum class Kernel { kTcone, kNcone };
enum class Impl { kScalar, kSimd };

using KernelFn = void (*)(const PatchBatchView&, Vec3, std::uint8_t*);

KernelFn kernel_fn(Kernel k, Impl impl) {
    if (k == Kernel::kTcone) return impl == Impl::kScalar ? cull_tcone_scalar : cull_tcone_simd;
    return impl == Impl::kScalar ? cull_ncone_scalar : cull_ncone_simd;
}
const char* kernel_name(Kernel k) { return k == Kernel::kTcone ? "tcone" : "ncone"; }

// Runs a kernel; guard bytes after count must stay untouched.
std::vector<std::uint8_t> run(Kernel k, Impl impl, const PatchBatchView& view, Vec3 eye) {
    constexpr std::size_t kGuard = 64;
    std::vector<std::uint8_t> out(view.count + kGuard, 0xAB);
    kernel_fn(k, impl)(view, eye, out.data());
    for (std::size_t i = view.count; i < out.size(); ++i) EXPECT_EQ(out[i], 0xAB) << "wrote past count at " << i;
    out.resize(view.count);
    return out;
}

// As in frustum_test: body(fast) once per compiled and supported SIMD target, dispatch forced to
// it; fast is false for the targets without an FMA instruction (SSSE3, SSE4, scalar), which run
// std::fma per lane and are slow, so callers may give them fewer patches.
void for_each_simd_target(const std::function<void(bool)>& body) {
    for (std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(std::string("SIMD target ") + hwy::TargetName(target));
        ASSERT_STREQ(simd_target_name(), hwy::TargetName(target));
        const bool fast = target == HWY_AVX2 || target == HWY_AVX3 || target == HWY_AVX3_DL;
        body(fast);
    }
    hwy::SetSupportedTargetsForTest(0);
}

// Largest e . T over a grid x grid lattice, relative to |n| |e - p| (double precision; > 0 means a
// sample faces the eye). Samples with n = 0 count as 0.
double max_facing(const BezierPatch& patch, Vec3 eye, int grid) {
    double worst = -1;
    for (int j = 0; j < grid; ++j)
        for (int i = 0; i < grid; ++i) {
            const SurfaceD s = evaluate_d(patch, double(i) / (grid - 1), double(j) / (grid - 1));
            const D3 n = s.normal(), w = d3(eye) - s.p;
            const double scale = len(n) * len(w);
            worst = std::max(worst, scale > 0 ? dot(n, w) / scale : 0.0);
        }
    return worst;
}

// Eyes around a patch: far, just outside its sphere, close in front of / behind the surface.
std::vector<Vec3> eyes_for(const BezierPatch& patch, PatchGen& gen) {
    const PatchSphere s = control_point_sphere(patch);
    const D3 c = d3(s.center);
    const double r = std::max(double(s.radius), 1e-3);
    std::vector<Vec3> eyes;
    auto add = [&eyes](D3 e) { eyes.push_back({float(e.x), float(e.y), float(e.z)}); };
    for (double k : {1.0002, 1.01, 1.2, 3.0, 30.0, 3000.0}) add(c + gen.unit() * (r * k));
    // Behind the patch along (minus) the cone axis, near and far: where culling happens.
    const NormalCone n = normal_patch_cone(patch);
    if (n.valid)
        for (double k : {1.0002, 1.001, 1.05, 2.0, 100.0}) add(c - (d3(n.axis) + gen.unit() * 0.05) * (r * k));
    // Close to the surface, both sides.
    for (int q = 0; q < 4; ++q) {
        const SurfaceD sd = evaluate_d(patch, gen.uniform(0, 1), gen.uniform(0, 1));
        const D3 nn = sd.normal();
        if (len(nn) == 0) continue;
        const D3 nh = nn * (1 / len(nn));
        const double delta = r * std::pow(10.0, gen.uniform(-4, 0));
        add(sd.p - nh * delta);
        add(sd.p + nh * delta);
    }
    return eyes;
}

struct Tally {
    long tests = 0, culled = 0;
};

// Runs both implementations of kernel k on one patch for every eye; whenever it culls, no
// sample of the 17x17 grid (and of a 33x33 grid) faces the eye.
void check_conservative(Kernel k, const BezierPatch& patch, const std::vector<Vec3>& eyes, Tally& tally,
                        const char* what, int index) {
    const PatchBatch batch = make_batch({patch});
    for (const Vec3& eye : eyes) {
        const auto scalar = run(k, Impl::kScalar, batch.view(), eye);
        const auto simd = run(k, Impl::kSimd, batch.view(), eye);
        ASSERT_EQ(scalar[0], simd[0]) << kernel_name(k) << " " << what << " " << index;
        ++tally.tests;
        if (!scalar[0]) continue;
        ++tally.culled;
        const double f17 = max_facing(patch, eye, kGroundTruthGrid);
        ASSERT_LE(f17, 1e-9) << kernel_name(k) << " false cull: " << what << " " << index << " eye (" << eye.x << ", "
                             << eye.y << ", " << eye.z << ")";
        ASSERT_LE(max_facing(patch, eye, 33), 1e-9) << kernel_name(k) << " " << what << " " << index;
        // The project's ground truth (tangent planes from cross4) agrees.
        PlaneD planes[kGroundTruthGrid * kGroundTruthGrid];
        sample_tangent_planes(patch, kGroundTruthGrid, planes);
        ASSERT_FALSE(any_plane_faces_eye(planes, kGroundTruthGrid * kGroundTruthGrid, eye)) << what << " " << index;
    }
}

TEST(BackpatchCones, ConservativeOnRandomPatches) {
    PatchGen gen(101);
    Tally tally[2];
    for (int trial = 0; trial < 2000 / kSanitizerDivisor; ++trial) {
        const BezierPatch patch = gen.any();
        const std::vector<Vec3> eyes = eyes_for(patch, gen);
        for (Kernel k : {Kernel::kTcone, Kernel::kNcone}) {
            check_conservative(k, patch, eyes, tally[int(k)], "random patch", trial);
            if (HasFatalFailure()) return;
        }
    }
    std::printf("[ conservative ] random patches: tcone culled %ld of %ld tests, ncone %ld of %ld\n", tally[0].culled,
                tally[0].tests, tally[1].culled, tally[1].tests);
    EXPECT_GT(tally[0].culled, tally[0].tests / 20);
    EXPECT_GT(tally[1].culled, tally[0].culled);
}

TEST(BackpatchCones, ConservativeOnTeapot) {
    PatchGen gen(102);
    const std::vector<BezierPatch> teapot = teapot_patches();
    Tally tally[2];
    // Eyes all around the teapot (2..40 units from its centre) and close to every patch.
    std::vector<Vec3> around;
    for (int q = 0; q < 200 / kSanitizerDivisor; ++q) {
        const D3 e = D3{0, 0, 1.5} + gen.unit() * gen.uniform(2, 40);
        around.push_back({float(e.x), float(e.y), float(e.z)});
    }
    for (std::size_t p = 0; p < teapot.size(); ++p) {
        std::vector<Vec3> eyes = around;
        for (int rep = 0; rep < 5; ++rep)
            for (const Vec3& e : eyes_for(teapot[p], gen)) eyes.push_back(e);
        for (Kernel k : {Kernel::kTcone, Kernel::kNcone}) {
            check_conservative(k, teapot[p], eyes, tally[int(k)], "teapot patch", int(p));
            if (HasFatalFailure()) return;
        }
    }
    std::printf("[ conservative ] teapot: tcone culled %ld of %ld tests, ncone %ld of %ld\n", tally[0].culled,
                tally[0].tests, tally[1].culled, tally[1].tests);
    EXPECT_GT(tally[1].culled, 0);
}

// A flat quarter disc collapsed at its centre (degenerate like the teapot's lid and bottom):
// NCONE culls it from behind and never from the front.
TEST(BackpatchCones, CollapsedEdgeCulledFromBehind) {
    BezierPatch fan;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const double a = (kPi / 2) * i / 3.0, r = 1.5 * j / 3.0;
            fan.cp[4 * j + i] = {float(r * std::cos(a)), float(r * std::sin(a)), 0.0f, 1.0f};
        }
    const float side = evaluate_d(fan, 0.5, 0.5).normal().z > 0 ? 1.0f : -1.0f;  // outward side
    const PatchBatch batch = make_batch({fan, fan, fan});
    for (Impl impl : {Impl::kScalar, Impl::kSimd}) {
        const auto behind = run(Kernel::kNcone, impl, batch.view(), {0.3f, 0.2f, -5 * side});
        const auto front = run(Kernel::kNcone, impl, batch.view(), {0.3f, 0.2f, 5 * side});
        for (int p = 0; p < 3; ++p) {
            EXPECT_EQ(behind[p], 1) << p;
            EXPECT_EQ(front[p], 0) << p;
        }
    }
}

// Batch of n patches: mostly random, some rational (weights 0.5..2), a few with NaN/inf, some
// degenerate teapot patches.
std::vector<BezierPatch> mixed_patches(PatchGen& gen, std::size_t n) {
    const std::vector<BezierPatch> teapot = teapot_patches();
    std::vector<BezierPatch> out(n);
    for (std::size_t p = 0; p < n; ++p) {
        const int kind = gen.integer(0, 99);
        BezierPatch patch = kind < 3 ? teapot[std::size_t(gen.integer(0, 31))] : gen.any();
        if (kind >= 3 && kind < 13) {
            for (auto& c : patch.cp) c = c * float(gen.uniform(0.5, 2));
        } else if (kind == 13) {
            patch.cp[gen.integer(0, 15)].w = 1.0000001f;  // "almost polynomial" is rational
        } else if (kind == 14) {
            const float bad[3] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                                  -std::numeric_limits<float>::infinity()};
            patch.cp[gen.integer(0, 15)].z = bad[gen.integer(0, 2)];
        }
        out[p] = patch;
    }
    return out;
}

TEST(BackpatchCones, ScalarAndSimdIdentical) {
    PatchGen gen(201);
    // Not a multiple of any lane count; >= 100k in the Release suite.
    constexpr std::size_t kCount = kSanitizerDivisor == 1 ? 100003 : 20011;
    const std::vector<BezierPatch> patches = mixed_patches(gen, kCount);
    const PatchBatch batch = make_batch(patches);
    const Vec3 eyes[2] = {{0, 0, 0}, {-1.5f, 3, 0.25f}};
    long culled[2] = {0, 0}, rational_culled = 0;
    for (Kernel k : {Kernel::kTcone, Kernel::kNcone}) {
        for (const Vec3& eye : eyes) {
            const auto ref = run(k, Impl::kScalar, batch.view(), eye);
            for (std::size_t p = 0; p < kCount; ++p) {
                culled[int(k)] += ref[p];
                bool polynomial = true;
                for (const Vec4& c : patches[p].cp) polynomial = polynomial && c.w == 1.0f;
                if (!polynomial) rational_culled += ref[p];
            }
            for_each_simd_target([&](bool fast) {
                // All patches on the FMA targets, the first fifth on the slow ones.
                const std::size_t n_t = fast ? kCount : kCount / 5;
                const auto simd = run(k, Impl::kSimd, batch.view().subrange(0, n_t), eye);
                std::size_t diff = 0, first = n_t;
                for (std::size_t p = 0; p < n_t; ++p)
                    if (simd[p] != ref[p]) {
                        ++diff;
                        first = std::min(first, p);
                    }
                ASSERT_EQ(diff, 0u) << kernel_name(k) << ": " << diff << " differences, first at " << first;
                // Subranges at odd offsets and counts.
                for (std::size_t first_p : {std::size_t(0), std::size_t(1), std::size_t(7), std::size_t(333)})
                    for (std::size_t n : {std::size_t(1), std::size_t(3), std::size_t(15), std::size_t(16),
                                          std::size_t(17), std::size_t(31), std::size_t(33), std::size_t(1000)}) {
                        const auto sub = run(k, Impl::kSimd, batch.view().subrange(first_p, n), eye);
                        for (std::size_t p = 0; p < n; ++p)
                            ASSERT_EQ(sub[p], ref[first_p + p])
                                << kernel_name(k) << " subrange " << first_p << "+" << n;
                    }
            });
        }
    }
    std::printf("[ identical ] %zu patches x 2 eyes: tcone culled %ld, ncone culled %ld (rational culled %ld)\n",
                kCount, culled[0], culled[1], rational_culled);
    EXPECT_EQ(rational_culled, 0);
    EXPECT_GT(culled[0], 1000);
    EXPECT_GT(culled[1], culled[0]);
    // mixed_patches puts rational patches in about 10 % of the slots: all of them were checked.
}

// Eyes on the decision boundary (angle(a, d) = 90deg + alpha + beta, jittered by ~1e-4 rad):
// every decision is a close call, where any difference in rounding would show.
TEST(BackpatchCones, ScalarAndSimdIdenticalOnTheBoundary) {
    PatchGen gen(202);
    for (Kernel k : {Kernel::kTcone, Kernel::kNcone}) {
        std::vector<BezierPatch> patches;
        while (patches.size() < std::size_t(20001 / kSanitizerDivisor)) {
            BezierPatch patch = gen.sheet(std::pow(10.0, gen.uniform(-3, -0.5)), std::pow(10.0, gen.uniform(-1, 1)));
            const NormalCone cone = k == Kernel::kTcone ? tangent_normal_cone(patch) : normal_patch_cone(patch);
            if (!cone.valid) continue;
            const PatchSphere s = control_point_sphere(patch);
            const double alpha = std::atan2(cone.sin_angle, cone.cos_angle);
            const double L = s.radius * gen.uniform(1.5, 20);
            const double beta = std::asin(s.radius / L);
            const double phi = kPi / 2 + alpha + beta + gen.uniform(-2e-5, 1e-4);  // angle(a, d)
            if (phi >= kPi) continue;
            const D3 a = d3(cone.axis);
            D3 perp = cross(a, gen.unit());
            perp = perp * (1 / len(perp));
            const D3 eye = d3(s.center) + (a * std::cos(phi) + perp * std::sin(phi)) * L;
            // Move the patch so that the eye is the origin.
            for (auto& c : patch.cp) c = {float(c.x - eye.x), float(c.y - eye.y), float(c.z - eye.z), 1.0f};
            patches.push_back(patch);
        }
        const PatchBatch batch = make_batch(patches);
        const auto ref = run(k, Impl::kScalar, batch.view(), {0, 0, 0});
        long culled = 0;
        for (auto c : ref) culled += c;
        std::printf("[ boundary ] %s: %ld of %zu culled\n", kernel_name(k), culled, patches.size());
        EXPECT_GT(culled, long(patches.size() / 10));
        EXPECT_LT(culled, long(patches.size() * 9 / 10));
        for_each_simd_target([&](bool) {
            const auto simd = run(k, Impl::kSimd, batch.view(), {0, 0, 0});
            std::size_t diff = 0;
            for (std::size_t p = 0; p < patches.size(); ++p) diff += simd[p] != ref[p];
            ASSERT_EQ(diff, 0u) << kernel_name(k);
        });
    }
}

TEST(BackpatchCones, KernelsMatchPublicConeFunctions) {
    PatchGen gen(301);
    const std::vector<BezierPatch> patches = mixed_patches(gen, 5000 / kSanitizerDivisor);
    const PatchBatch batch = make_batch(patches);
    for (const Vec3 eye : {Vec3{0, 0, 0}, Vec3{3, 1, -2}}) {
        const auto t = run(Kernel::kTcone, Impl::kScalar, batch.view(), eye);
        const auto n = run(Kernel::kNcone, Impl::kScalar, batch.view(), eye);
        for (std::size_t p = 0; p < patches.size(); ++p) {
            const PatchSphere s = control_point_sphere(patches[p]);
            EXPECT_EQ(t[p], cone_back_facing(tangent_normal_cone(patches[p]), s, eye) ? 1 : 0) << p;
            EXPECT_EQ(n[p], cone_back_facing(normal_patch_cone(patches[p]), s, eye) ? 1 : 0) << p;
        }
    }
}

TEST(BackpatchCones, RationalNeverCulled) {
    // A flat square facing +z seen from below: culled; the same geometry with weights != 1 (points
    // scaled by w, so the Cartesian patch is the same plane) is not.
    BezierPatch flat;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) flat.cp[4 * j + i] = {float(i), float(j), 0, 1};
    BezierPatch rational = flat;
    for (int k = 0; k < 16; ++k) rational.cp[k] = rational.cp[k] * (k % 3 == 0 ? 2.0f : 1.0f);
    const PatchBatch batch = make_batch({flat, rational, flat});
    for (Kernel k : {Kernel::kTcone, Kernel::kNcone})
        for (Impl impl : {Impl::kScalar, Impl::kSimd}) {
            const auto out = run(k, impl, batch.view(), {1.5f, 1.5f, -10});
            EXPECT_EQ(out[0], 1);
            EXPECT_EQ(out[1], 0);
            EXPECT_EQ(out[2], 1);
            const auto front = run(k, impl, batch.view(), {1.5f, 1.5f, 10});
            EXPECT_EQ(front[0] + front[1] + front[2], 0);
        }
}

TEST(BackpatchCones, EmptyBatch) {
    const PatchBatch batch(0);
    for (Kernel k : {Kernel::kTcone, Kernel::kNcone})
        for (Impl impl : {Impl::kScalar, Impl::kSimd}) EXPECT_TRUE(run(k, impl, batch.view(), {0, 0, 0}).empty());
}

}  // namespace
