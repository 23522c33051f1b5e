// The Vulkan frustum-disp, tcone, ncone and ptp passes (patchcull/vk/vk_passes.h) on lavapipe with
// the validation layers on: each leaves the flag words of its CPU scalar kernel (begin -> pass on
// words with no reason), in every ClipDepth convention where the kernel takes one, for both ptp
// rules, on a Vulkan y-down projection too; displaced patches are left to the other passes by the
// back-patch ones; the diagnostics equal the CPU's arithmetic bit for bit where it is exposed.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <random>

#include "core/ptp_internal.h"
#include "core/test_patches.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/teapot.h"
#include "vk/vk_cases.h"

using namespace patchcull;
using namespace patchcull::vk;
using namespace patchcull::vk::test;

namespace {

constexpr ClipDepth kConventions[] = {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed,
                                      ClipDepth::reversed_infinite};

// begin -> record(cmd, buffers) on the case's buffers (words with no reason); the flag words.
std::vector<std::uint32_t> vk_words(Context& vk, const RandomCase& c,
                                    const std::function<void(VkCommandBuffer, const PatchBuffers&)>& record) {
    CaseBuffers b(c);
    CullStatusPass status(vk.passes());
    vk.submit([&](VkCommandBuffer cmd) {
        status.begin(cmd, b.patch_buffers());
        record(cmd, b.patch_buffers());
    });
    return b.flags.read<std::uint32_t>(c.patches.size());
}

// A closed surface seen from many sides, and rational copies: the teapot split twice (512 patches)
// and its 32 originals, a third of them rational.
RandomCase teapot_case(std::uint32_t seed, bool with_margins) {
    RandomCase c;
    c.patches = test_patches::split_teapot(2);
    for (const BezierPatch& p : teapot_patches()) c.patches.push_back(p);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> w(0.5f, 2.0f);
    for (std::size_t p = 0; p < c.patches.size(); p += 3)
        for (Vec4& cp : c.patches[p].cp) {
            const float k = w(rng);
            cp = {cp.x * k, cp.y * k, cp.z * k, k};
        }
    std::uniform_real_distribution<float> u(-1, 1);
    if (with_margins)
        for (std::size_t p = 0; p < c.patches.size(); ++p) c.margins.push_back(p % 4 == 0 ? 0.01f : 0.0f);
    c.camera.eye = Vec3{u(rng), u(rng), u(rng)} * 6.0f;
    c.camera.target = {0, 0, 1};
    return c;
}

std::uint32_t bits(float f) {
    std::uint32_t b;
    std::memcpy(&b, &f, 4);
    return b;
}

class VkBackpatch : public VkTest {};

}  // namespace

TEST_F(VkBackpatch, FrustumDispWordsEqualCpuScalarKernelInEveryConvention) {
    std::size_t culled = 0, total = 0;
    for (const ClipDepth depth : kConventions)
        for (std::uint32_t seed = 31; seed <= 33; ++seed) {
            const RandomCase c = random_case(seed, 1500, depth, seed != 32);
            const Mat4 m = c.camera.view_projection();
            FrustumDispPass pass(vk().passes());
            const std::vector<std::uint32_t> gpu =
                vk_words(vk(), c, [&](VkCommandBuffer cmd, const PatchBuffers& b) { pass.run(cmd, b, m, depth); });
            std::vector<std::uint8_t> cpu(c.patches.size());
            cull_frustum_disp_scalar(patch_batch(c.patches).view(), c.margins.empty() ? nullptr : c.margins.data(), m,
                                     depth, cpu.data());
            const std::vector<std::uint32_t> expected = words_of(cpu, kCullFrustum);
            for (std::size_t p = 0; p < cpu.size(); ++p) {
                ASSERT_EQ(gpu[p], expected[p]) << clip_depth_name(depth) << " seed " << seed << " patch " << p;
                culled += cpu[p];
            }
            total += cpu.size();
        }
    EXPECT_GT(culled, total / 10);
    EXPECT_LT(culled, total * 9 / 10);
}

TEST_F(VkBackpatch, ConeWordsEqualCpuScalarKernels) {
    for (const BackpatchMethod method : {BackpatchMethod::tcone, BackpatchMethod::ncone}) {
        std::size_t culled = 0, total = 0;
        for (std::uint32_t seed = 1; seed <= 4; ++seed) {
            const RandomCase c = teapot_case(seed, false);
            const Vec3 eye = c.camera.eye;
            BackpatchConePass pass(vk().passes());
            HostBuffer cones(c.patches.size() * 12 * sizeof(float));
            const std::vector<std::uint32_t> gpu = vk_words(vk(), c, [&](VkCommandBuffer cmd, const PatchBuffers& b) {
                pass.run(cmd, b, method, eye, cones.range());
            });
            std::vector<std::uint8_t> cpu(c.patches.size());
            if (method == BackpatchMethod::tcone)
                cull_tcone_scalar(patch_batch(c.patches).view(), eye, cpu.data());
            else
                cull_ncone_scalar(patch_batch(c.patches).view(), eye, cpu.data());
            const std::vector<std::uint32_t> expected = words_of(cpu, kCullBackPatch);
            for (std::size_t p = 0; p < cpu.size(); ++p) {
                ASSERT_EQ(gpu[p], expected[p]) << backpatch_method_name(method) << " seed " << seed << " patch " << p;
                culled += cpu[p];
            }
            total += cpu.size();
        }
        EXPECT_GT(culled, total / 5) << backpatch_method_name(method);
    }
}

TEST_F(VkBackpatch, ConesAndPtpLeaveDisplacedPatchesAlone) {
    const RandomCase c = teapot_case(7, true);
    const Vec3 eye = c.camera.eye;
    const Mat4 projection = c.camera.projection();
    const Mat4 m = projection * c.camera.view();
    std::vector<std::uint8_t> cpu(c.patches.size());
    cull_tcone_scalar(patch_batch(c.patches).view(), eye, cpu.data());
    BackpatchConePass cones(vk().passes());
    const std::vector<std::uint32_t> gpu = vk_words(
        vk(), c, [&](VkCommandBuffer cmd, const PatchBuffers& b) { cones.run(cmd, b, BackpatchMethod::tcone, eye); });
    std::size_t displaced_back = 0;
    for (std::size_t p = 0; p < cpu.size(); ++p) {
        const bool displaced = c.margins[p] > 0.0f;
        ASSERT_EQ(gpu[p], displaced ? 0u : (cpu[p] ? kCullBackPatch : 0u)) << "tcone patch " << p;
        displaced_back += displaced && cpu[p];
    }
    EXPECT_GT(displaced_back, 10u);
    cull_ptp_scalar(patch_batch(c.patches).view(), m, clip_space_eye_alpha(projection), PtpRule::pcnt, cpu.data());
    BackpatchPtpPass ptp(vk().passes());
    const std::vector<std::uint32_t> gpu_ptp = vk_words(vk(), c, [&](VkCommandBuffer cmd, const PatchBuffers& b) {
        EXPECT_TRUE(ptp.run(cmd, b, m, clip_space_eye_alpha(projection), PtpRule::pcnt));
    });
    for (std::size_t p = 0; p < cpu.size(); ++p)
        ASSERT_EQ(gpu_ptp[p], c.margins[p] > 0.0f ? 0u : (cpu[p] ? kCullBackPatch : 0u)) << "ptp patch " << p;
}

TEST_F(VkBackpatch, PtpWordsAndPlanesEqualCpuScalarKernelAlsoYDown) {
    // ptp takes no ClipDepth: the convention enters through alpha's sign (forward < 0, reversed >
    // 0) and the y-down flip through det; each run costs about a second on lavapipe (exact fma
    // in double), so four runs cover both signs of each, and both rules.
    struct Run {
        ClipDepth depth;
        bool y_down;
        PtpRule rule;
    };
    const Run runs[] = {{ClipDepth::zero_to_one, false, PtpRule::ncnt},
                        {ClipDepth::zero_to_one, true, PtpRule::pcnt},
                        {ClipDepth::reversed_infinite, false, PtpRule::pcnt},
                        {ClipDepth::reversed, true, PtpRule::ncnt}};
    std::size_t culled = 0, total = 0;
    for (const Run& run : runs) {
        RandomCase c = teapot_case(11, false);
        c.camera.depth = run.depth;
        Mat4 projection = c.camera.projection();
        if (run.y_down)
            for (int col = 0; col < 4; ++col) projection.at(1, col) = -projection.at(1, col);
        const Mat4 m = projection * c.camera.view();
        const float alpha = clip_space_eye_alpha(projection);
        const std::string where = std::string(clip_depth_name(run.depth)) + (run.y_down ? " y-down" : " y-up") +
                                  (run.rule == PtpRule::pcnt ? " pcnt" : " ncnt");
        BackpatchPtpPass pass(vk().passes());
        HostBuffer planes(c.patches.size() * 128 * sizeof(float));
        const std::vector<std::uint32_t> gpu = vk_words(vk(), c, [&](VkCommandBuffer cmd, const PatchBuffers& b) {
            EXPECT_TRUE(pass.run(cmd, b, m, alpha, run.rule, planes.range()));
        });
        std::vector<std::uint8_t> cpu(c.patches.size());
        cull_ptp_scalar(patch_batch(c.patches).view(), m, alpha, run.rule, cpu.data());
        const std::vector<std::uint32_t> expected = words_of(cpu, kCullBackPatch);
        for (std::size_t p = 0; p < cpu.size(); ++p) {
            ASSERT_EQ(gpu[p], expected[p]) << where << " patch " << p;
            culled += cpu[p];
        }
        total += cpu.size();
        // The 64 control plane z values of each patch, as the CPU kernel computes them.
        ptp_detail::PtpClipRows rows;
        ASSERT_TRUE(ptp_detail::ptp_clip_rows(m, alpha, rows));
        const std::vector<float> got = planes.read<float>(c.patches.size() * 128);
        for (std::size_t p = 0; p < c.patches.size(); ++p) {
            float t[64];
            ptp_detail::ptp_control_planes_z(c.patches[p], rows, t);
            for (int d = 0; d < 64; ++d)
                ASSERT_EQ(bits(got[128 * p + d]), bits(t[d])) << where << " patch " << p << " d " << d;
        }
    }
    EXPECT_GT(culled, total / 5);
}

TEST_F(VkBackpatch, PtpRecordsNothingForADegenerateView) {
    const RandomCase c = teapot_case(3, false);
    Mat4 singular = c.camera.view_projection();
    for (int col = 0; col < 4; ++col) singular.at(1, col) = 0.0f;
    BackpatchPtpPass pass(vk().passes());
    const std::vector<std::uint32_t> gpu = vk_words(vk(), c, [&](VkCommandBuffer cmd, const PatchBuffers& b) {
        EXPECT_FALSE(pass.run(cmd, b, singular, clip_space_eye_alpha(c.camera.projection()), PtpRule::pcnt));
    });
    for (std::size_t p = 0; p < gpu.size(); ++p) ASSERT_EQ(gpu[p], 0u) << "patch " << p;
}
