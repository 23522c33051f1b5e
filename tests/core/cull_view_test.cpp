// CullView (core/cull_view.h) and the back-patch registry (core/backpatch_methods.h): the view's
// parts equal what each kernel made for itself, the kernels' CullView entry points and the
// registry's built-in methods decide exactly as the kernels called directly, in every depth
// convention, and a view without an eye culls nothing by the cone tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/test_patches.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/hiz.h"

namespace patchcull {
namespace {

constexpr ClipDepth kConventions[] = {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed,
                                      ClipDepth::reversed_infinite};

TEST(CullView, HoldsWhatEachKernelMadeForItself) {
    const Mat4 view = look_at({1, 2, 7}, {0, 0.5f, 0}, {0, 1, 0});
    for (ClipDepth depth : kConventions) {
        const Mat4 projection = perspective(0.9f, 1.3f, 0.1f, 50.0f, depth);
        const CullView v = make_cull_view(view, projection, depth);
        const Mat4 object_to_clip = projection * view;
        for (int k = 0; k < 16; ++k) EXPECT_EQ(v.object_to_clip.m[k], object_to_clip.m[k]);
        const FrustumPlanes planes = make_frustum_planes(object_to_clip, depth);
        for (int q = 0; q < 6; ++q) EXPECT_EQ(v.planes.rows[q].w, planes.rows[q].w);
        ASSERT_TRUE(v.has_eye);
        EXPECT_NEAR(v.eye.x, 1.0f, 1e-5f);
        EXPECT_NEAR(v.eye.y, 2.0f, 1e-5f);
        EXPECT_NEAR(v.eye.z, 7.0f, 1e-5f);
        EXPECT_EQ(v.alpha, clip_space_eye_alpha(projection));
        EXPECT_EQ(v.orientation, ptp_orientation_sign(object_to_clip, v.alpha));
        EXPECT_NE(v.orientation, 0);
    }
}

TEST(CullView, EntryPointsAndRegistryDecideAsTheKernels) {
    const std::vector<BezierPatch> patches = test_patches::split_teapot(2);
    const PatchBatch batch = make_batch(patches);
    const std::size_t n = patches.size();
    for (ClipDepth depth : kConventions) {
        const Mat4 view = look_at({2, 3, 5}, {0, 1, 0}, {0, 1, 0});
        const Mat4 projection = perspective(0.5f, 1.0f, 0.5f, 20.0f, depth);
        const CullView v = make_cull_view(view, projection, depth);
        std::vector<std::uint8_t> a(n), b(n);
        cull_frustum(batch.view(), nullptr, v, a.data());
        cull_frustum_simd(batch.view(), nullptr, v.planes, b.data());
        EXPECT_EQ(a, b);
        cull_frustum_disp(batch.view(), nullptr, v, a.data());
        cull_frustum_disp_simd(batch.view(), nullptr, v.object_to_clip, depth, b.data());
        EXPECT_EQ(a, b);
        for (BackpatchMethod id : backpatch_method_ids()) {
            const BackpatchMethodInfo& info = backpatch_method_info(id);
            for (PtpRule rule : {PtpRule::ncnt, PtpRule::pcnt}) {
                cull_backpatch(id, batch.view(), v, BackpatchOptions{rule}, a.data());
                info.scalar(batch.view(), v, BackpatchOptions{rule}, b.data());
                EXPECT_EQ(a, b) << info.name;
            }
        }
        cull_backpatch(BackpatchMethod::tcone, batch.view(), v, {}, a.data());
        cull_tcone_simd(batch.view(), v.eye, b.data());
        EXPECT_EQ(a, b);
        cull_backpatch(BackpatchMethod::ptp, batch.view(), v, {PtpRule::pcnt}, a.data());
        cull_ptp_simd(batch.view(), v.object_to_clip, v.alpha, PtpRule::pcnt, b.data());
        EXPECT_EQ(a, b);
        EXPECT_GT(std::count(a.begin(), a.end(), 1), 0) << "not vacuous";
    }
}

TEST(CullView, NoEyeNoConeCulls) {
    CullView v;  // has_eye false: a singular view
    const std::vector<BezierPatch> patches = test_patches::split_teapot(1);
    const PatchBatch batch = make_batch(patches);
    std::vector<std::uint8_t> culled(patches.size(), 7);
    for (BackpatchMethod id : {BackpatchMethod::tcone, BackpatchMethod::ncone}) {
        cull_backpatch(id, batch.view(), v, {}, culled.data());
        EXPECT_EQ(std::count(culled.begin(), culled.end(), 0), static_cast<long>(patches.size()));
    }
    Mat4 singular;
    for (float& x : singular.m) x = 0;
    EXPECT_FALSE(make_cull_view(singular, perspective(0.5f, 1, 0.1f, 10), ClipDepth::zero_to_one).has_eye);
}

TEST(BackpatchRegistry, NamesAndRefusals) {
    const std::vector<BackpatchMethod> ids = backpatch_method_ids();
    ASSERT_GE(ids.size(), 3u);
    EXPECT_STREQ(backpatch_method_name(BackpatchMethod::tcone), "tcone");
    EXPECT_STREQ(backpatch_method_name(BackpatchMethod::ncone), "ncone");
    EXPECT_STREQ(backpatch_method_name(BackpatchMethod::ptp), "ptp");
    EXPECT_STREQ(backpatch_method_name(static_cast<BackpatchMethod>(1000)), "?");
    BackpatchMethod m = BackpatchMethod::ptp;
    EXPECT_FALSE(parse_backpatch_method("nope", m));
    EXPECT_FALSE(parse_backpatch_method(nullptr, m));
    EXPECT_EQ(m, BackpatchMethod::ptp);
    EXPECT_TRUE(parse_backpatch_method("ncone", m));
    EXPECT_EQ(m, BackpatchMethod::ncone);
    EXPECT_TRUE(backpatch_method_info(BackpatchMethod::tcone).fusable);
    EXPECT_FALSE(backpatch_method_info(BackpatchMethod::ptp).fusable);
    EXPECT_THROW(backpatch_method_info(static_cast<BackpatchMethod>(1000)), Error);
    EXPECT_THROW(register_backpatch_method({"", "", nullptr}), Error);
    EXPECT_THROW(register_backpatch_method({"tcone", "", backpatch_method_info(BackpatchMethod::tcone).scalar}), Error);
}

}  // namespace
}  // namespace patchcull
