// The parallel entries (parallel_cull.h) decide exactly as the single-threaded ones, on plain and
// blocked views, over several ranges and a ragged tail, with and without displacement bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/error.h"
#include "patchcull/core/parallel_cull.h"
#include "test_patches.h"

using namespace patchcull;

namespace {

constexpr int kW = 96, kH = 64;

// Copies of the split teapot scattered through a box around the eye, some with a poisoned point,
// so every kernel culls some patches and keeps others.
std::vector<BezierPatch> scattered_patches(std::size_t count, unsigned seed) {
    const std::vector<BezierPatch> teapot = test_patches::split_teapot(2);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-12, 12);
    std::vector<BezierPatch> out;
    out.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
        BezierPatch p = teapot[i % teapot.size()];
        const Vec3 shift{u(rng), u(rng), u(rng)};
        for (Vec4& c : p.cp) c = {c.x + shift.x, c.y + shift.y, c.z + shift.z, c.w};
        if (i % 97 == 5) p.cp[7].y = NAN;
        out.push_back(p);
    }
    return out;
}

struct Fixture {
    CullView view;
    HiZPyramid hiz;
    std::vector<float> displacement;
};

Fixture make_fixture(std::size_t count) {
    Fixture f;
    Camera cam;
    cam.eye = {0.5f, -3, 1};
    cam.target = {0, 4, 0};
    cam.up = {0, 0, 1};
    cam.aspect = float(kW) / float(kH);
    f.view = make_cull_view(cam.view(), cam.projection(), cam.depth, cam.eye);
    std::vector<float> depth(static_cast<std::size_t>(kW) * kH, 1.0f);
    for (int y = 10; y < 50; ++y)
        for (int x = 20; x < 80; ++x) depth[static_cast<std::size_t>(y) * kW + x] = 0.9f;
    f.hiz.build(depth.data(), kW, kH, cam.depth);
    for (std::size_t i = 0; i < count; ++i) f.displacement.push_back(0.05f * float(i % 7));
    return f;
}

template <class Single, class Parallel>
void expect_same(const PatchBatchView& patches, const Single& single, const Parallel& parallel, const char* what) {
    std::vector<std::uint8_t> a(patches.count, 0xEE), b(patches.count, 0xDD);
    single(patches, a.data());
    parallel(patches, b.data());
    std::size_t culled = 0, differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        culled += a[i] != 0;
        differ += a[i] != b[i];
    }
    EXPECT_EQ(differ, 0u) << what << ", " << patches.count << " patches" << (patches.blocked() ? ", blocked" : "");
    // The comparison means something only when the kernel culls some patches and keeps others.
    EXPECT_GT(culled, 0u) << what;
    EXPECT_LT(culled, a.size()) << what;
}

void check_every_kernel(const PatchBatchView& patches, const Fixture& f) {
    const CullView& v = f.view;
    const float* d = f.displacement.data();
    expect_same(
        patches, [&](const PatchBatchView& p, std::uint8_t* o) { cull_frustum(p, nullptr, v, o); },
        [&](const PatchBatchView& p, std::uint8_t* o) { cull_frustum_parallel(p, nullptr, v, o); }, "frustum");
    expect_same(
        patches, [&](const PatchBatchView& p, std::uint8_t* o) { cull_frustum(p, d, v, o); },
        [&](const PatchBatchView& p, std::uint8_t* o) { cull_frustum_parallel(p, d, v, o); }, "frustum, displaced");
    expect_same(
        patches, [&](const PatchBatchView& p, std::uint8_t* o) { cull_frustum_disp(p, d, v, o); },
        [&](const PatchBatchView& p, std::uint8_t* o) { cull_frustum_disp_parallel(p, d, v, o); }, "frustum-disp");
    for (BackpatchMethod id : backpatch_method_ids())
        expect_same(
            patches, [&](const PatchBatchView& p, std::uint8_t* o) { cull_backpatch(id, p, v, {}, o); },
            [&](const PatchBatchView& p, std::uint8_t* o) { cull_backpatch_parallel(id, p, v, {}, o); },
            backpatch_method_name(id));
    expect_same(
        patches, [&](const PatchBatchView& p, std::uint8_t* o) { cull_occlusion(p, v, f.hiz, o); },
        [&](const PatchBatchView& p, std::uint8_t* o) { cull_occlusion_parallel(p, v, f.hiz, o); }, "occlusion");
    const FusedCullSetup setup = make_fused_setup(v, BackPatchCone::tcone, &f.hiz);
    FusedPlan plans[6];
    const int n = fused_plans_of(0x7, plans);
    for (int k = 0; k < n; ++k)
        expect_same(
            patches, [&](const PatchBatchView& p, std::uint8_t* o) { cull_fused_simd(p, setup, plans[k], o); },
            [&](const PatchBatchView& p, std::uint8_t* o) { cull_fused_parallel(p, setup, plans[k], o); },
            ("fused " + fused_plan_name(plans[k])).c_str());
}

}  // namespace

TEST(ParallelCull, SameDecisionsAsTheSingleThreadedKernels) {
    // One range, exactly one grain, and several grains with a ragged tail.
    for (std::size_t count : {std::size_t{1450}, kParallelGrain, 3 * kParallelGrain + 37}) {
        const std::vector<BezierPatch> patches = scattered_patches(count, static_cast<unsigned>(count));
        const Fixture f = make_fixture(count);
        const PatchBatch plain = make_batch(patches);
        check_every_kernel(plain.view(), f);
        const PatchBlocks blocked(plain.view());
        check_every_kernel(blocked.view(), f);
    }
}

TEST(ParallelCull, RefusesWhatTheKernelsRefuse) {
    const std::vector<BezierPatch> patches = scattered_patches(2 * kParallelGrain, 3);
    const PatchBatch batch = make_batch(patches);
    Fixture f = make_fixture(batch.size());
    std::vector<std::uint8_t> out(batch.size());
    HiZPyramid unbuilt;
    EXPECT_THROW(cull_occlusion_parallel(batch.view(), f.view, unbuilt, out.data()), Error);
    FusedPlan bad;
    bad.stages[0] = bad.stages[1] = bad.stages[2] = FusedStage::frustum;
    const FusedCullSetup setup = make_fused_setup(f.view, BackPatchCone::tcone, &f.hiz);
    EXPECT_THROW(cull_fused_parallel(batch.view(), setup, bad, out.data()), Error);
    EXPECT_THROW(cull_backpatch_parallel(static_cast<BackpatchMethod>(1000), batch.view(), f.view, {}, out.data()),
                 Error);
}
