// The strict test of the fused pass in the frame (PipelineParams::fused_pass): on the
// default scene and a small city, both schemes (acc, osd), at the origin and 3000+ units from it,
// at low tessellation (1) on a small image (128x80) and high tessellation (8) on a large one
// (480x272), every frame's id buffer with the fused pass shows every patch the unculled frame
// shows (compare_frames: no false cull), and the frame equals the separate chain's (a second pipeline in lockstep: the
// same flag words and counts). Also `render --fused-pass --verify` through the CLI, and the fallback to the separate
// passes for ptp and the aabb frustum test.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"
#include "gl_test_util.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_verification.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_poser.h"

namespace patchcull::gl {
namespace {

constexpr float kSecondsPerFrame = 1.0f / 12.0f;

struct Case {
    const char* scene;  // "default" or "city" (small)
    Scheme scheme;
    Vec3 offset;  // the whole scene, occluders and cameras moved by it
    int tess, width, height;
};

std::string describe(const Case& c) {
    return std::string(c.scene) + (c.scheme == Scheme::acc ? " acc" : " osd") + " offset (" +
           std::to_string(int(c.offset.x)) + "," + std::to_string(int(c.offset.y)) + "," +
           std::to_string(int(c.offset.z)) + ") tess " + std::to_string(c.tess) + " " + std::to_string(c.width) + "x" +
           std::to_string(c.height);
}

Scene make_scene(const Case& c) {
    if (std::string(c.scene) == "default") return make_default_scene(c.scheme);
    CityParams city;
    city.blocks_x = 2;
    city.blocks_z = 2;
    city.characters = 8;
    return make_city_scene(c.scheme, city);
}

// One pipeline per role for the whole test binary (programs compile once on llvmpipe).
CullPipeline& pipeline(int role) {
    static CullPipeline fused(test::context());
    static CullPipeline separate(test::context());
    return role == 0 ? fused : separate;
}

// Runs `frames` frames of the case's camera path on both pipelines; returns the patches culled
// by the fused frames (all reasons).
std::size_t run_case(const Case& c, int frames) {
    const std::string what = describe(c);
    Scene scene = make_scene(c);
    for (Vec3& v : scene.occluder_vertices) v = v + c.offset;
    ScenePoser poser(scene);
    bool one_sided = true;
    for (const LoadedModel& m : scene.models) one_sided = one_sided && m.closed;
    const CullMode mode = one_sided ? CullMode::all : static_cast<CullMode>(kCullFrustum | kCullOcclusion);
    std::vector<TriangleSpan> one_sided_occluders;
    for (const EnvironmentObject& e : scene.environment)
        if (e.one_sided && e.triangle_count) one_sided_occluders.push_back({e.first_triangle, e.triangle_count});
    std::vector<Camera> cameras = scene.camera_path(frames, float(c.width) / float(c.height));
    std::size_t culled = 0;
    for (int f = 0; f < frames; ++f) {
        std::vector<BezierPatch> pose = poser.pose(float(f) * kSecondsPerFrame);
        for (BezierPatch& p : pose)
            for (Vec4& q : p.cp) q = {q.x + c.offset.x * q.w, q.y + c.offset.y * q.w, q.z + c.offset.z * q.w, q.w};
        PatchAttributes attributes;
        attributes.tangent_index = poser.tangent_index();
        attributes.tangents = poser.tangents();
        attributes.depth = poser.depth();
        if (!poser.displacement_ranges().empty()) {
            attributes.texcoords = poser.texcoords();
            attributes.displacement_ranges = poser.displacement_ranges();
        }
        Camera cam = cameras[static_cast<std::size_t>(f)];
        cam.eye = cam.eye + c.offset;
        cam.target = cam.target + c.offset;
        PipelineParams params;
        params.frame.render.view = cam.view();
        params.frame.render.projection = cam.projection();
        params.frame.render.width = c.width;
        params.frame.render.height = c.height;
        params.frame.render.tess_level = c.tess;
        params.frame.render.discard_back_facing = one_sided;
        params.frame.cull = mode;
        params.frame.timing = TimingMethod::off;
        FrameStats stats[2];
        std::vector<std::uint32_t> words[2];
        for (int role = 0; role < 2; ++role) {
            CullPipeline& pl = pipeline(role);
            if (f == 0) {
                pl.set_patches(pose, attributes);
                pl.renderer().set_displacement_map(scene.displacement);
                pl.renderer().set_occluders(scene.occluder_vertices, scene.occluder_indices, one_sided_occluders);
            } else {
                pl.update_patches(pose, attributes);
            }
            params.fused_pass = role == 0;
            stats[role] = pl.render_frame(params);
            words[role] = pl.renderer().read_cull_flags();
        }
        const std::string at = what + ", frame " + std::to_string(f);
        EXPECT_TRUE(stats[0].fused_pass) << at;
        EXPECT_FALSE(stats[1].fused_pass) << at;
        // The fused frame is the chain's frame.
        EXPECT_TRUE(words[0] == words[1]) << at << ": flag words differ from the separate chain's";
        EXPECT_EQ(stats[0].frustum_culled, stats[1].frustum_culled) << at;
        EXPECT_EQ(stats[0].backpatch_culled, stats[1].backpatch_culled) << at;
        EXPECT_EQ(stats[0].occlusion_culled, stats[1].occlusion_culled) << at;
        EXPECT_EQ(stats[0].visible, stats[1].visible) << at;
        EXPECT_EQ(stats[0].pass2_drawn, stats[1].pass2_drawn) << at;
        // The strict test: every patch of the unculled frame's front set was drawn.
        PatchRenderer& r = pipeline(0).renderer();
        const FrameCapture frame = {r.read_ids(), r.read_depth(), r.read_drawn_patches()};
        RenderParams reference_params = params.frame.render;
        reference_params.use_cull_flags = false;
        r.render(reference_params);
        const FrameCapture reference = {r.read_ids(), r.read_depth(), r.mark_front_patches(reference_params)};
        const FrameComparison cmp = compare_frames(reference, frame);
        EXPECT_TRUE(cmp.false_culled.empty()) << at << ": " << cmp.false_culled.size() << " false culls, first patch "
                                              << (cmp.false_culled.empty() ? 0u : cmp.false_culled[0]);
        culled += stats[0].frustum_culled + stats[0].backpatch_culled + stats[0].occlusion_culled;
    }
    return culled;
}

// Low tessellation on a small image and high tessellation on a large one, each at the origin and
// far from it. osd makes 4.5x the patches of acc (37350 on the default scene), so it runs one
// frame per case on llvmpipe, acc two (the second with the first frame's statuses).
void run_cases(const char* scene, Scheme scheme) {
    const int frames = scheme == Scheme::acc ? 2 : 1;
    const Vec3 origin{0, 0, 0}, far{3000, -2000, 3000};
    for (Vec3 offset : {origin, far}) {
        const Case low{scene, scheme, offset, 1, 128, 80};
        const Case high{scene, scheme, offset, 8, 480, 272};
        EXPECT_GT(run_case(low, frames), 0u) << describe(low);
        EXPECT_GT(run_case(high, frames), 0u) << describe(high);
    }
}

TEST(FusedPipeline, StrictOnTheDefaultSceneAcc) { run_cases("default", Scheme::acc); }
TEST(FusedPipeline, StrictOnTheDefaultSceneOsd) { run_cases("default", Scheme::osd); }
TEST(FusedPipeline, StrictOnASmallCityAcc) { run_cases("city", Scheme::acc); }
TEST(FusedPipeline, StrictOnASmallCityOsd) { run_cases("city", Scheme::osd); }

TEST(FusedPipeline, PtpAndAabbKeepTheSeparatePasses) {
    CullPipeline& pl = pipeline(0);
    pl.set_patches(test::split_teapot(1));
    pl.renderer().set_displacement_map({});  // an earlier test's map would turn every test off
    pl.renderer().set_occluders({}, {});
    PipelineParams params;
    Camera cam;
    cam.eye = {0, -6, 2};
    cam.target = {0, 0, 1};
    cam.up = {0, 0, 1};
    params.frame.render.view = cam.view();
    params.frame.render.projection = cam.projection();
    params.frame.render.width = params.frame.render.height = 64;
    params.frame.render.tess_level = 2;
    params.frame.timing = TimingMethod::off;
    params.fused_pass = true;
    EXPECT_TRUE(pl.render_frame(params).fused_pass);
    params.backpatch = BackpatchMethod::ptp;
    EXPECT_FALSE(pl.render_frame(params).fused_pass);
    params.frame.cull = static_cast<CullMode>(kCullFrustum | kCullOcclusion);  // ptp unused: fused again
    EXPECT_TRUE(pl.render_frame(params).fused_pass);
    params.frustum = FrustumTest::aabb;
    EXPECT_FALSE(pl.render_frame(params).fused_pass);
    params.fused_pass = false;
    params.frustum = FrustumTest::hull;
    EXPECT_FALSE(pl.render_frame(params).fused_pass);
}

TEST(FusedPipeline, RenderFusedPassVerifyHasNoFalseCulls) {
    using namespace patchcull::cli_test;
    const CliRun r = run("render default --size 96x64 --tess 2 --frames 2 --fused-pass --verify --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["fused_pass"], true);
    EXPECT_EQ(j["verified"], true);
    EXPECT_EQ(j["false_culls"], 0);
    ASSERT_EQ(j["frames"].size(), 2u);
    for (const auto& frame : j["frames"]) EXPECT_EQ(frame["fused_pass"], true) << frame.dump();
    // ptp keeps the separate passes: the flag is on, the frames say they did not fuse.
    const CliRun p = run("render default --size 64x48 --tess 2 --frames 1 --fused-pass --backpatch ptp --json");
    ASSERT_EQ(p.status, 0) << p.err;
    const auto k = nlohmann::json::parse(p.out);
    EXPECT_EQ(k["frames"][0]["fused_pass"], false);
}

}  // namespace
}  // namespace patchcull::gl
