// The blocked patch layout (patchcull/core/patch.h: PatchBatchView::block_stride, PatchBlocks):
// at()/get()/set() round trips on both layouts and through subranges; and identical decisions of
// every kernel that reads patches through at() or the SIMD groups (tcone, ncone, ptp with both
// rules, scalar and every compiled SIMD target; the SIMD frustum kernels, which share
// ForEachGroup) on the plain and the blocked copy of random batches of 1, 15, 16, 17, 1000 and
// 4099 patches, whole and in subranges starting at multiples of 16, with and without software
// prefetching of plain views.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

constexpr float kPi = 3.14159265358979f;
// Debug + sanitizer builds (the ASan + UBSan run of scripts/test.sh) are ~30x slower: the largest
// batches run in the Release build only (there the whole list runs).
#if defined(__SANITIZE_ADDRESS__) || !defined(NDEBUG)
const std::size_t kSizes[] = {1, 15, 16, 17, 300};
#else
const std::size_t kSizes[] = {1, 15, 16, 17, 1000, 4099};
#endif

// Curved sheets of random size and orientation in a box around the origin, one in eight rational
// (weights 0.5..2): some face the eye at the origin, some face away, some straddle the frustum.
std::vector<BezierPatch> random_patches(std::size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    std::vector<BezierPatch> patches(n);
    for (auto& patch : patches) {
        const Vec3 c{8 * u(rng), 8 * u(rng), 8 * u(rng) - 10};
        const float size = 0.2f + 1.5f * unit(rng);
        const Vec3 a = Vec3{u(rng), u(rng), u(rng)} * size, b = Vec3{u(rng), u(rng), u(rng)} * size;
        const Vec3 nrm = cross(a, b);
        const bool rational = unit(rng) < 0.125f;
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const float s = i / 3.0f - 0.5f, t = j / 3.0f - 0.5f;
                const Vec3 pt = c + a * s + b * t + nrm * (0.3f * (s * s + t * t) + 0.02f * u(rng));
                patch.cp[4 * j + i] = homogeneous(pt, rational ? 0.5f + 1.5f * unit(rng) : 1.0f);
            }
    }
    return patches;
}

void expect_same_patch(const BezierPatch& a, const BezierPatch& b) {
    for (int k = 0; k < kPatchPoints; ++k) {
        EXPECT_EQ(a.cp[k].x, b.cp[k].x);
        EXPECT_EQ(a.cp[k].y, b.cp[k].y);
        EXPECT_EQ(a.cp[k].z, b.cp[k].z);
        EXPECT_EQ(a.cp[k].w, b.cp[k].w);
    }
}

void expect_view_holds(const PatchBatchView& v, const std::vector<BezierPatch>& patches, std::size_t first) {
    ASSERT_LE(first + v.count, patches.size());
    for (std::size_t p = 0; p < v.count; ++p) {
        const BezierPatch& want = patches[first + p];
        for (int k = 0; k < kPatchPoints; ++k) {
            ASSERT_EQ(v.at(p, k, 0), want.cp[k].x) << p << " " << k;
            ASSERT_EQ(v.at(p, k, 1), want.cp[k].y) << p << " " << k;
            ASSERT_EQ(v.at(p, k, 2), want.cp[k].z) << p << " " << k;
            ASSERT_EQ(v.at(p, k, 3), want.cp[k].w) << p << " " << k;
        }
    }
}

TEST(BlockedLayout, ViewsDescribeTheirLayout) {
    const PatchBlocks blocks(17);
    const PatchBatchView v = blocks.view();
    EXPECT_TRUE(v.blocked());
    EXPECT_EQ(v.count, 17u);
    EXPECT_EQ(v.stride, kBlockPatches);
    EXPECT_EQ(v.block_stride, kBlockFloats);
    EXPECT_EQ(kBlockFloats, 1024u);
    EXPECT_EQ(blocks.blocks(), 2u);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data) % 64, 0u) << "blocks start on a cache line";
    const PatchBatch batch(17);
    EXPECT_FALSE(batch.view().blocked());
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(batch.view().data) % 64, 0u) << "arrays start on a cache line";
    // Padding lanes of the last block are zero.
    for (int a = 0; a < 64; ++a)
        for (std::size_t j = 1; j < kBlockPatches; ++j) EXPECT_EQ(v.data[kBlockFloats + a * kBlockPatches + j], 0.0f);
}

TEST(BlockedLayout, RoundTripsOnBothLayouts) {
    for (std::size_t n : kSizes) {
        SCOPED_TRACE("n = " + std::to_string(n));
        const std::vector<BezierPatch> patches = random_patches(n, 11 + static_cast<unsigned>(n));
        const PatchBatch batch = make_batch(patches);
        PatchBlocks blocks(n);
        for (std::size_t p = 0; p < n; ++p) blocks.set(p, patches[p]);
        const PatchBlocks converted(batch.view());
        expect_view_holds(batch.view(), patches, 0);
        expect_view_holds(blocks.view(), patches, 0);
        expect_view_holds(converted.view(), patches, 0);
        for (std::size_t p = 0; p < n; ++p) {
            expect_same_patch(blocks.get(p), patches[p]);
            expect_same_patch(converted.get(p), patches[p]);
            expect_same_patch(get_patch(blocks.view(), p), patches[p]);
            expect_same_patch(get_patch(batch.view(), p), patches[p]);
        }
        // Back to plain, and blocked from blocked.
        const PatchBatch plain_again = copy_to_batch(blocks.view());
        expect_view_holds(plain_again.view(), patches, 0);
        const PatchBlocks blocks_again(blocks.view());
        expect_view_holds(blocks_again.view(), patches, 0);
        // Subranges at multiples of 16 (blocked) and at any offset (plain).
        for (std::size_t first = 0; first < n; first += 16) {
            const std::size_t len = (n - first) / 2 + 1;
            expect_view_holds(blocks.view().subrange(first, len), patches, first);
            expect_view_holds(batch.view().subrange(first, len), patches, first);
        }
        if (n > 3) expect_view_holds(batch.view().subrange(3, n - 3), patches, 3);
    }
}

TEST(BlockedLayoutDeathTest, BlockedSubrangeMustStartAtABlock) {
    const PatchBlocks blocks(40);
    EXPECT_DEBUG_DEATH((void)blocks.view().subrange(3, 10), "block");
}

// ---- kernels: plain vs blocked ---------------------------------------------------------------

using Kernel = std::function<void(const PatchBatchView&, std::uint8_t*)>;

struct NamedKernel {
    std::string name;
    Kernel fn;
    bool slow;  // ncone and ptp on targets without FMA: fewer patches
};

std::vector<NamedKernel> kernels() {
    const Vec3 eye{0.3f, -0.2f, 0.5f};
    const Mat4 proj = perspective(60.0f * kPi / 180, 1.5f, 0.05f, 500.0f);
    const Mat4 object_to_clip = proj * look_at(eye, {0, 0, -10}, {0, 1, 0});
    const float alpha = clip_space_eye_alpha(proj);
    auto ptp = [=](bool simd, PtpRule rule) {
        return [=](const PatchBatchView& v, std::uint8_t* out) {
            (simd ? cull_ptp_simd : cull_ptp_scalar)(v, object_to_clip, alpha, rule, out);
        };
    };
    std::vector<NamedKernel> k;
    k.push_back(
        {"tcone_scalar", [=](const PatchBatchView& v, std::uint8_t* o) { cull_tcone_scalar(v, eye, o); }, false});
    k.push_back({"tcone_simd", [=](const PatchBatchView& v, std::uint8_t* o) { cull_tcone_simd(v, eye, o); }, false});
    k.push_back(
        {"ncone_scalar", [=](const PatchBatchView& v, std::uint8_t* o) { cull_ncone_scalar(v, eye, o); }, true});
    k.push_back({"ncone_simd", [=](const PatchBatchView& v, std::uint8_t* o) { cull_ncone_simd(v, eye, o); }, true});
    k.push_back({"ptp_ncnt_scalar", ptp(false, PtpRule::ncnt), true});
    k.push_back({"ptp_ncnt_simd", ptp(true, PtpRule::ncnt), true});
    k.push_back({"ptp_pcnt_scalar", ptp(false, PtpRule::pcnt), true});
    k.push_back({"ptp_pcnt_simd", ptp(true, PtpRule::pcnt), true});
    // The SIMD frustum kernels read through ForEachGroup too (their scalar references are not
    // part of this file's contract).
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, ClipDepth::zero_to_one);
    auto disp = std::make_shared<std::vector<float>>(8192, 0.05f);
    k.push_back({"frustum_simd",
                 [=](const PatchBatchView& v, std::uint8_t* o) { cull_frustum_simd(v, disp->data(), planes, o); },
                 false});
    k.push_back({"frustum_disp_simd",
                 [=](const PatchBatchView& v, std::uint8_t* o) {
                     cull_frustum_disp_simd(v, disp->data(), object_to_clip, ClipDepth::zero_to_one, o);
                 },
                 false});
    return k;
}

std::vector<std::uint8_t> run(const Kernel& fn, const PatchBatchView& v) {
    std::vector<std::uint8_t> out(v.count + 32, 0xAB);
    fn(v, out.data());
    for (std::size_t i = v.count; i < out.size(); ++i) EXPECT_EQ(out[i], 0xAB) << "wrote past count at " << i;
    out.resize(v.count);
    return out;
}

// Every kernel, plain and blocked copies, whole batches and subranges at multiples of 16.
void check_plain_equals_blocked(bool fast_target) {
    for (const NamedKernel& k : kernels()) {
        SCOPED_TRACE(k.name);
        std::size_t culled_total = 0, total = 0;
        for (std::size_t n : kSizes) {
            if (k.slow && !fast_target && n > 1000) continue;
            SCOPED_TRACE("n = " + std::to_string(n));
            const std::vector<BezierPatch> patches = random_patches(n, 101 + static_cast<unsigned>(n));
            const PatchBatch batch = make_batch(patches);
            const PatchBlocks blocks(batch.view());
            const std::vector<std::uint8_t> plain = run(k.fn, batch.view());
            ASSERT_EQ(plain, run(k.fn, blocks.view()));
            for (std::uint8_t c : plain) culled_total += c;
            total += n;
            for (std::size_t first = 0; first < n; first += (n > 100 ? 16 * 13 : 16)) {
                for (std::size_t len : {std::size_t{1}, std::size_t{17}, n - first}) {
                    if (first + len > n) continue;
                    const std::vector<std::uint8_t> want(plain.begin() + first, plain.begin() + first + len);
                    ASSERT_EQ(want, run(k.fn, blocks.view().subrange(first, len)))
                        << "first " << first << " len " << len;
                    ASSERT_EQ(want, run(k.fn, batch.view().subrange(first, len)))
                        << "first " << first << " len " << len;
                }
            }
        }
        // The comparison has teeth: the kernel culls some patches and keeps others.
        EXPECT_GT(culled_total, 0u);
        EXPECT_LT(culled_total, total);
    }
}

void for_each_simd_target(const std::function<void(bool)>& body) {
    for (std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(std::string("SIMD target ") + hwy::TargetName(target));
        const bool fast = (target & (HWY_SSSE3 | HWY_SSE4 | HWY_EMU128 | HWY_SCALAR)) == 0;
        body(fast);
    }
    hwy::SetSupportedTargetsForTest(0);
}

TEST(BlockedLayout, KernelsDecideTheSameOnBothLayouts) {
    for_each_simd_target([](bool fast) { check_plain_equals_blocked(fast); });
}

// Prefetching plain and blocked views (ForEachGroup) changes no decision, at distances short, long and past
// the end of the batch.
TEST(BlockedLayout, PrefetchChangesNoDecision) {
    const std::size_t saved = plain_prefetch_distance(), saved_blocked = blocked_prefetch_distance();
    const std::vector<BezierPatch> patches = random_patches(kSizes[std::size(kSizes) - 1], 7);
    const PatchBatch batch = make_batch(patches);
    std::vector<std::vector<std::uint8_t>> want;
    const PatchBlocks blocks(batch.view());
    set_plain_prefetch_distance(0);
    set_blocked_prefetch_distance(0);
    const std::vector<NamedKernel> ks = kernels();
    want.reserve(ks.size());
    for (const NamedKernel& k : ks) want.push_back(run(k.fn, batch.view()));
    for (std::size_t distance : {std::size_t{16}, std::size_t{128}, std::size_t{100000}}) {
        set_plain_prefetch_distance(distance);
        set_blocked_prefetch_distance(distance);
        EXPECT_EQ(plain_prefetch_distance(), distance);
        EXPECT_EQ(blocked_prefetch_distance(), distance);
        for (std::size_t i = 0; i < ks.size(); ++i) {
            EXPECT_EQ(want[i], run(ks[i].fn, batch.view())) << ks[i].name;
            EXPECT_EQ(want[i], run(ks[i].fn, blocks.view())) << ks[i].name;
        }
    }
    set_plain_prefetch_distance(saved);
    set_blocked_prefetch_distance(saved_blocked);
}

}  // namespace
