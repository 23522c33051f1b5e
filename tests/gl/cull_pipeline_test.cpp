// CullPipeline (patchcull/gl/gl_pipeline.h): the GPU back-patch pass in the frame of Niessner & Loop,
// "Patch-Based Occlusion Culling for Hardware Tessellation" §3 (the flag
// chain of gl_passes.h), and the per-object switch (PipelineParams::objects). For tcone, ncone and ptp: the frame culls
// exactly the patches the CPU scalar kernel culls (every patch is inside the frustum), the final id buffer equals the
// unculled render's (no false cull), and after update_patches the pass reads the new pose.
// Small: BigGuy (1450 patches; a closed surface, as back-patch culling requires), 64x64, level 2.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/displacement.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_verification.h"
#include "patchcull/import/model_loader.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

constexpr int kSize = 64;

CullPipeline& pipeline() {
    static CullPipeline p(test::context());
    return p;
}

RenderParams params_for(const Camera& camera) {
    RenderParams rp;
    rp.view = camera.view();
    rp.projection = camera.projection();
    rp.width = rp.height = kSize;
    rp.tess_level = 2;
    return rp;
}

// The CPU scalar kernel's decision per patch.
std::vector<std::uint8_t> cpu_culled_set(BackpatchMethod method, const std::vector<BezierPatch>& patches,
                                         const RenderParams& rp) {
    const PatchBatch batch = make_batch(patches);
    std::vector<std::uint8_t> culled(patches.size());
    const Mat4 object_to_clip = rp.projection * rp.view;
    switch (method) {
        case BackpatchMethod::tcone:
            cull_tcone_scalar(batch.view(), eye_of_view(rp.view), culled.data());
            break;
        case BackpatchMethod::ncone:
            cull_ncone_scalar(batch.view(), eye_of_view(rp.view), culled.data());
            break;
        case BackpatchMethod::ptp:
            cull_ptp_scalar(batch.view(), object_to_clip, clip_space_eye_alpha(rp.projection), PtpRule::ncnt,
                            culled.data());
            break;
    }
    return culled;
}

std::size_t cpu_culled(BackpatchMethod method, const std::vector<BezierPatch>& patches, const RenderParams& rp) {
    std::size_t n = 0;
    for (std::uint8_t c : cpu_culled_set(method, patches, rp)) n += c ? 1 : 0;
    return n;
}

// Rotates every control point by 90 degrees about the z axis through c (w kept).
std::vector<BezierPatch> turned(std::vector<BezierPatch> patches, Vec3 c) {
    for (BezierPatch& p : patches)
        for (Vec4& q : p.cp) {
            const Vec3 d = cartesian(q) - c;
            q = homogeneous(c + Vec3{-d.y, d.x, d.z}, q.w);
        }
    return patches;
}

const std::vector<BezierPatch>& bigguy() {
    static const std::vector<BezierPatch> patches =
        load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0).rest.patches;
    return patches;
}

}  // namespace

TEST(CullPipeline, EyeOfViewIsTheCameraPosition) {
    Camera camera;
    camera.eye = {1.5f, -2.0f, 3.25f};
    camera.target = {0.1f, 0.2f, 0.3f};
    const Vec3 eye = eye_of_view(camera.view());
    EXPECT_NEAR(eye.x, camera.eye.x, 1e-5f);
    EXPECT_NEAR(eye.y, camera.eye.y, 1e-5f);
    EXPECT_NEAR(eye.z, camera.eye.z, 1e-5f);
    Mat4 singular;
    singular.at(1, 1) = 0;
    EXPECT_THROW(eye_of_view(singular), Error);
}

TEST(CullPipeline, BackPatchPassFeedsTheFrameForEveryMethod) {
    const std::vector<BezierPatch>& rest = bigguy();
    const std::vector<Camera> cameras = orbit_sequence(test::control_point_bounds(rest), 1, 0.0f);
    const RenderParams rp = params_for(cameras[0]);
    for (const BackpatchMethod method : {BackpatchMethod::tcone, BackpatchMethod::ncone, BackpatchMethod::ptp}) {
        for (const bool turn : {false, true}) {
            CullPipeline& p = pipeline();
            const std::vector<BezierPatch> pose = turn ? turned(rest, test::control_point_bounds(rest).center()) : rest;
            if (turn) {
                p.update_patches(pose);  // a new pose of the same patches: the pass must read it
            } else {
                p.set_patches(pose);
            }
            PipelineParams params;
            params.frame.render = rp;
            params.frame.cull = CullMode::backpatch;
            params.frame.timing = TimingMethod::wall_clock;
            params.backpatch = method;
            const FrameStats s = p.render_frame(params);
            const char* name = backpatch_method_name(method);
            EXPECT_EQ(s.frustum_culled, 0u) << name;  // the whole teapot is in view
            EXPECT_EQ(s.backpatch_culled, cpu_culled(method, pose, rp)) << name << (turn ? " turned" : "");
            EXPECT_GT(s.backpatch_culled, 0u) << name;
            EXPECT_EQ(s.backpatch_culled + s.visible, pose.size()) << name;
            EXPECT_GT(s.backpatch_ms, 0.0) << name;
            EXPECT_GE(s.cull_ms, s.backpatch_ms) << name;

            const FrameCapture culled = {p.renderer().read_ids(), p.renderer().read_depth(),
                                         p.renderer().read_drawn_patches()};
            RenderParams unculled = rp;
            unculled.use_cull_flags = false;
            p.renderer().render(unculled);
            const FrameCapture reference = {p.renderer().read_ids(), p.renderer().read_depth(),
                                            p.renderer().mark_front_patches(unculled)};
            const FrameComparison cmp = compare_frames(reference, culled);
            EXPECT_TRUE(cmp.false_culled.empty()) << name << ": " << cmp.false_culled.size() << " false culls";
            EXPECT_TRUE(cmp.conservative()) << name;
        }
    }
}

TEST(CullPipeline, BackPatchPassRunsOnTheUndisplacedRunsWithTheSameDecisions) {
    // Displaced patches (margin > 0) before c, in [c + 100, c + 110) and after c2, where c and c2
    // are patches every method culls: the undisplaced run [c, c2] holds the run of 10 (too short
    // to dispatch around), the others are left out of the back-patch pass. The frame still culls
    // exactly the undisplaced patches the CPU kernel culls, patch by patch, for every method (c
    // and c2 among them: a run dispatched one patch short fails).
    const std::vector<BezierPatch>& rest = bigguy();
    const RenderParams rp = params_for(orbit_sequence(test::control_point_bounds(rest), 1, 0.0f)[0]);
    const std::vector<BackpatchMethod> methods = {BackpatchMethod::tcone, BackpatchMethod::ncone, BackpatchMethod::ptp};
    std::vector<std::vector<std::uint8_t>> cpu;
    for (const BackpatchMethod method : methods) cpu.push_back(cpu_culled_set(method, rest, rp));
    auto culled_by_all = [&](std::size_t i) { return cpu[0][i] && cpu[1][i] && cpu[2][i]; };
    std::size_t c = 300, c2 = rest.size() - 300;
    while (c < c2 && !culled_by_all(c)) ++c;
    while (c2 > c && !culled_by_all(c2)) --c2;
    ASSERT_GT(c2, c + 300);
    PatchAttributes attributes;
    attributes.max_displacement.assign(rest.size(), 0.0f);
    for (const PatchSpan run : {PatchSpan{0, c}, PatchSpan{c + 100, 10}, PatchSpan{c2 + 1, rest.size() - c2 - 1}})
        for (std::size_t i = run.first; i < run.first + run.count; ++i) attributes.max_displacement[i] = 0.01f;
    CullPipeline& p = pipeline();
    p.set_patches(rest, attributes);
    p.renderer().set_displacement_map(make_procedural_displacement(16, 0.001f));
    const std::vector<PatchSpan>& runs = p.renderer().undisplaced_runs();
    ASSERT_EQ(runs.size(), 1u);
    EXPECT_EQ(runs[0].first, c);
    EXPECT_EQ(runs[0].count, c2 + 1 - c);
    for (std::size_t m = 0; m < methods.size(); ++m) {
        PipelineParams params;
        params.frame.render = rp;
        params.frame.cull = CullMode::backpatch;
        params.frame.timing = TimingMethod::wall_clock;
        params.backpatch = methods[m];
        const FrameStats s = p.render_frame(params);
        const char* name = backpatch_method_name(methods[m]);
        EXPECT_EQ(s.frustum_culled, 0u) << name;
        const std::vector<std::uint32_t> flags = p.renderer().read_cull_flags();
        std::size_t differ = 0;
        for (std::size_t i = 0; i < rest.size(); ++i) {
            const bool expected = cpu[m][i] && attributes.max_displacement[i] == 0.0f;
            differ += ((flags[i] & kCullReasonMask) == kCullBackPatch) != expected ? 1 : 0;
        }
        EXPECT_EQ(differ, 0u) << name;
        EXPECT_EQ(flags[c] & kCullReasonMask, kCullBackPatch) << name;
        EXPECT_EQ(flags[c2] & kCullReasonMask, kCullBackPatch) << name;
    }
    p.renderer().set_displacement_map(DisplacementMap{});
    p.set_patches(rest);
}

TEST(CullPipeline, ModesWithoutBackPatchRunNoPass) {
    const std::vector<BezierPatch>& rest = bigguy();
    CullPipeline& p = pipeline();
    p.set_patches(rest);
    PipelineParams params;
    params.frame.render = params_for(orbit_sequence(test::control_point_bounds(rest), 1, 0.0f)[0]);
    params.frame.timing = TimingMethod::wall_clock;
    params.backpatch = BackpatchMethod::ncone;
    for (const CullMode mode : {CullMode::none, CullMode::frustum, CullMode::occlusion}) {
        params.frame.cull = mode;
        const FrameStats s = p.render_frame(params);
        EXPECT_EQ(s.backpatch_culled, 0u) << cull_mode_name(mode);
        EXPECT_EQ(s.backpatch_ms, 0.0) << cull_mode_name(mode);
    }
}

TEST(CullPipeline, ObjectsSwitchCullingPerRangeAndCountApart) {
    // Three copies of BigGuy side by side as three objects: the middle one not culled. Its
    // patches are all drawn and counted visible, the others are culled as one set would be; the
    // per-object counts add up to the frame's; patches outside every object are drawn unculled.
    const std::vector<BezierPatch>& one = bigguy();
    const Bounds b = test::control_point_bounds(one);
    const float step = 1.2f * length(b.max - b.min);
    std::vector<BezierPatch> three;
    for (int c = 0; c < 3; ++c)
        for (BezierPatch patch : one) {
            for (Vec4& q : patch.cp) q = homogeneous(cartesian(q) + Vec3{step * static_cast<float>(c - 1), 0, 0}, q.w);
            three.push_back(patch);
        }
    CullPipeline& p = pipeline();
    p.set_patches(three);
    const std::size_t n = one.size();
    PipelineParams params;
    params.frame.render = params_for(orbit_sequence(test::control_point_bounds(three), 1, 0.0f)[0]);
    params.frame.render.discard_back_facing = true;
    params.frame.cull = CullMode::all;
    params.objects = {{0, n, true}, {n, n, false}, {2 * n, n, true}};
    p.render_frame(params);  // first frame
    const FrameStats s = p.render_frame(params);
    ASSERT_EQ(s.objects.size(), 3u);
    std::size_t frustum = 0, back = 0, occluded = 0, visible = 0;
    for (const ObjectStats& o : s.objects) {
        EXPECT_EQ(o.patches, n);
        EXPECT_EQ(o.frustum_culled + o.backpatch_culled + o.occlusion_culled + o.visible, n);
        frustum += o.frustum_culled;
        back += o.backpatch_culled;
        occluded += o.occlusion_culled;
        visible += o.visible;
    }
    EXPECT_EQ(s.objects[1].visible, n);  // not culled: all drawn
    EXPECT_GT(s.objects[0].backpatch_culled + s.objects[2].backpatch_culled, n / 4);
    EXPECT_EQ(frustum, s.frustum_culled);
    EXPECT_EQ(back, s.backpatch_culled);
    EXPECT_EQ(occluded, s.occlusion_culled);
    EXPECT_EQ(visible, s.visible);
    const std::vector<std::uint32_t> words = p.renderer().read_cull_flags();
    for (std::size_t i = n; i < 2 * n; ++i) ASSERT_EQ(words[i], kStatusVisible) << "patch " << i;
    // Patches between objects: drawn, not tested.
    params.objects = {{0, n, true}, {2 * n, n, true}};
    const FrameStats gap = p.render_frame(params);
    EXPECT_EQ(gap.objects.size(), 2u);
    EXPECT_GE(gap.visible, n);
    // Ranges that leave the set or overlap are refused.
    params.objects = {{0, n + 1, true}, {n, n, true}};
    EXPECT_THROW(p.render_frame(params), patchcull::Error);
    params.objects = {{2 * n, n + 1, true}};
    EXPECT_THROW(p.render_frame(params), patchcull::Error);
}
