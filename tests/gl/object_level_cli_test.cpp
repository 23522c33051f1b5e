// The object level through the CLI and on the GPU: `render
// SCENE --objects M --verify --json` on data/scenes/city_small.json for every method and variant,
// the built-in building (small parameters are not reachable from the CLI: a few frames of the
// default building at a tiny size), the default scene (acc and osd), with 0 false culls each
// against the unculled render of every frame; the per-frame "objects" JSON contract; detail
// culling reported as detail_pixels, never as false culls; bad flags as one-line errors with exit
// status 2. And the mutation test that --verify's ground truth would catch an object-level false
// cull: CullPipeline with a visible object's span in PipelineParams::object_culled (and a visible
// occluder triangle in culled_occluders), compared with the unculled render as the CLI does
// (compare_frames and the reference's id buffer). The object level follows G. Zachmann's lecture
// "Advanced Visibility Computations" before Niessner & Loop's patch passes
// ("Patch-Based Occlusion Culling for Hardware Tessellation"). Everything runs on
// llvmpipe at tiny sizes and tessellation 1-2 (seconds per run).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"
#include "gl_test_util.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_renderer.h"
#include "patchcull/gl/gl_verification.h"

using namespace patchcull::cli_test;

namespace {

std::string scene_file(const char* name) { return std::string(PATCHCULL_SOURCE_DIR) + "/data/scenes/" + name; }
std::string test_scene(const char* name) { return std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/scenes/" + name; }

// Object counts of one frame must be numbers, and consistent; objects: the scene's count (0: not
// checked exactly).
void check_objects_json(const nlohmann::json& frame, std::size_t objects, const std::string& what) {
    ASSERT_TRUE(frame.contains("objects")) << what << ": " << frame.dump();
    const nlohmann::json& o = frame["objects"];
    for (const char* key :
         {"total", "frustum_culled", "backface_culled", "detail_culled", "plane_tests", "bvh_nodes_visited",
          "cluster_tests", "patches_culled", "triangles_culled", "backface_patches_culled", "false_culled_objects",
          "false_culled_triangles", "detail_pixels"})
        ASSERT_TRUE(o.contains(key) && o[key].is_number_unsigned()) << what << ": " << key << " in " << o.dump();
    if (objects > 0) {
        EXPECT_EQ(o["total"].get<std::size_t>(), objects) << what;
    } else {
        EXPECT_GT(o["total"].get<std::size_t>(), 0u) << what;
    }
    EXPECT_LE(o["frustum_culled"].get<std::size_t>() + o["backface_culled"].get<std::size_t>() +
                  o["detail_culled"].get<std::size_t>(),
              o["total"].get<std::size_t>())
        << what;
    EXPECT_LE(o["backface_patches_culled"].get<std::size_t>(), o["patches_culled"].get<std::size_t>()) << what;
    ASSERT_TRUE(frame.contains("false_culls") && frame["false_culls"].is_number_unsigned()) << what;
    // The per-frame object counts sit beside the patch counts: the GPU saw the culled patches as
    // object-culled (every patch is counted once: passes, or object level).
    EXPECT_GT(o["bvh_nodes_visited"].get<std::size_t>(), 0u) << what;
}

struct Summary {
    std::size_t frustum = 0, backface = 0, backface_patches = 0, triangles = 0, detail = 0, detail_pixels = 0;
};

// Runs a verified render and checks: exit 0, 0 false culls in every frame (object level and patch
// level), the objects JSON in every frame. Returns the sums of the object counts.
Summary verified_render(const std::string& args, std::size_t objects, std::size_t frames) {
    Summary s;
    const CliRun r = run(args + " --verify --json");
    EXPECT_EQ(r.status, 0) << args << ": " << r.err << r.out.substr(0, 2000);
    if (r.status != 0 && r.out.empty()) return s;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["verified"], true) << args;
    EXPECT_EQ(j["false_culls"], 0) << args;
    EXPECT_EQ(j["frames"].size(), frames) << args;
    for (const auto& frame : j["frames"]) {
        const std::string what = args + ", frame " + frame["frame"].dump();
        EXPECT_EQ(frame["false_culls"], 0) << what;
        EXPECT_FALSE(frame.contains("false_culled_patches")) << what << ": " << frame["false_culled_patches"].dump();
        check_objects_json(frame, objects, what);
        if (!frame.contains("objects")) continue;
        const nlohmann::json& o = frame["objects"];
        EXPECT_EQ(o["false_culled_objects"], 0) << what;
        EXPECT_EQ(o["false_culled_triangles"], 0) << what;
        s.frustum += o["frustum_culled"].get<std::size_t>();
        s.backface += o["backface_culled"].get<std::size_t>();
        s.backface_patches += o["backface_patches_culled"].get<std::size_t>();
        s.triangles += o["triangles_culled"].get<std::size_t>();
        s.detail += o["detail_culled"].get<std::size_t>();
        s.detail_pixels += o["detail_pixels"].get<std::size_t>();
    }
    return s;
}

// city_small.json: 20 characters and 5 environment objects.
constexpr std::size_t kCitySmallObjects = 25;
const std::string kCitySmall = "render " + scene_file("city_small.json") + " --size 96x54 --tess 1 --frames 2 ";

}  // namespace

TEST(ObjectLevelCli, CitySmallEveryMethodHasNoFalseCulls) {
    for (const char* method : {"frustum", "bvh", "bvh+backface"}) {
        const Summary s = verified_render(kCitySmall + "--objects " + method, kCitySmallObjects, 2);
        // The camera walks the middle street: buildings and characters behind it leave the view.
        EXPECT_GT(s.frustum, 0u) << method;
        if (std::string(method) == "bvh+backface") {
            EXPECT_GT(s.triangles, 0u) << "the buildings' back faces";
        } else {
            EXPECT_EQ(s.backface, 0u) << method;
        }
    }
    // --objects none: the objects JSON is there (the contract lists none too), nothing is
    // culled by the object level, and 0 false culls.
    const CliRun r = run(kCitySmall + "--objects none --verify --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["false_culls"], 0);
    for (const auto& frame : j["frames"]) {
        ASSERT_TRUE(frame.contains("objects")) << frame.dump();
        const nlohmann::json& o = frame["objects"];
        for (const char* key :
             {"total", "frustum_culled", "backface_culled", "detail_culled", "plane_tests", "bvh_nodes_visited"})
            ASSERT_TRUE(o.contains(key) && o[key].is_number_unsigned()) << key << " in " << o.dump();
        EXPECT_EQ(o["total"], kCitySmallObjects);
        EXPECT_EQ(o["frustum_culled"], 0);
        EXPECT_EQ(o["backface_culled"], 0);
        EXPECT_EQ(o["patches_culled"], 0);
        EXPECT_EQ(o["triangles_culled"], 0);
    }
}

TEST(ObjectLevelCli, CitySmallEveryVariantHasNoFalseCulls) {
    const std::string bf = kCitySmall + "--objects bvh+backface ";
    const char* variants[] = {
        "--plane-masking off --plane-coherence off --meta-bv on",
        "--backface-triangles masks --mask-sectors 3 --object-volume obb",
        "--backface-triangles triangles --object-volume sphere",
        "--cluster-cost 0 --patch-cluster-cost 0 --cull frustum",
        // At tC/r 16 a building's faces merge into one cluster that never culls (documented).
        "--cluster-cost 16 --patch-cluster-cost 0.01 --cull auto",
    };
    for (const char* v : variants) {
        const Summary s = verified_render(bf + v, kCitySmallObjects, 2);
        EXPECT_GT(s.frustum, 0u) << v;
        if (std::string(v).find("--cluster-cost 16") == std::string::npos) {
            EXPECT_GT(s.triangles, 0u) << v;
        }
    }
}

// Detail culling is not conservative: what it removes is reported as detail_pixels, not as
// false culls (the run passes), and it culls the far characters of the street at 96x54.
TEST(ObjectLevelCli, DetailCullingIsReportedNotCountedAsFalseCulls) {
    const CliRun r = run(kCitySmall + "--objects bvh --detail-cull 40 --verify --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["false_culls"], 0);
    EXPECT_EQ(j["detail_cull"], 40.0);
    std::size_t detail = 0;
    for (const auto& frame : j["frames"]) {
        check_objects_json(frame, kCitySmallObjects, "detail");
        detail += frame["objects"]["detail_culled"].get<std::size_t>();
        EXPECT_EQ(frame["false_culls"], 0);
    }
    EXPECT_GT(detail, 0u);
}

// The built-in building (77 characters, 106k patches: a tiny frame, tessellation 1), the shipped
// building.json, and the default scene with both schemes, with back-face clusters.
TEST(ObjectLevelCli, BuildingAndDefaultSceneHaveNoFalseCulls) {
    const Summary built_in =
        verified_render("render building --objects bvh+backface --size 64x36 --tess 1 --frames 1", 0, 1);
    EXPECT_GT(built_in.frustum, 0u);
    EXPECT_GT(built_in.backface_patches, 0u) << "the rigid characters' patch clusters";
    const Summary b = verified_render(
        "render " + scene_file("building.json") + " --objects bvh+backface --size 96x54 --tess 2 --frames 3", 0, 3);
    EXPECT_GT(b.triangles, 0u);
    for (const char* scheme : {"acc", "osd"}) {
        const Summary d = verified_render(std::string("render default --scheme ") + scheme +
                                              " --objects bvh+backface --size 96x54 --tess 2 --frames 1",
                                          10, 1);
        EXPECT_GT(d.triangles, 0u) << scheme;
    }
}

TEST(ObjectLevelCli, BadObjectFlagsAreOneLineErrors) {
    const std::string r = "render " + scene_file("city_small.json") + " --size 32x18 --frames 1 --tess 1 ";
    expect_one_line_error(run(r + "--objects bogus --json"), "--objects");
    expect_one_line_error(run(r + "--objects bvh --detail-cull -1 --json"), "--detail-cull");
    expect_one_line_error(run(r + "--objects bvh --detail-cull nan --json"), "--detail-cull");
    expect_one_line_error(run(r + "--detail-cull 5 --json"), "--detail-cull");
    expect_one_line_error(run(r + "--objects bvh+backface --mask-sectors 0 --json"), "--mask-sectors");
    expect_one_line_error(run(r + "--objects bvh+backface --cluster-cost -1 --json"), "--cluster-cost");
    expect_one_line_error(run(r + "--objects bvh+backface --patch-cluster-cost -1 --json"), "--patch-cluster-cost");
    expect_one_line_error(run(r + "--objects bvh+backface --backface-triangles some --json"), "--backface-triangles");
    expect_one_line_error(run(r + "--objects bvh --plane-masking maybe --json"), "--plane-masking");
    expect_one_line_error(run(r + "--objects bvh --object-volume cone --json"), "--object-volume");
    // A variant flag the method would ignore is an error, not a silent no-op.
    expect_one_line_error(run(r + "--mask-sectors 2 --json"), "--mask-sectors: needs --objects bvh+backface");
    expect_one_line_error(run(r + "--objects bvh+backface --mask-sectors 2 --json"),
                          "--mask-sectors: needs --backface-triangles masks");
    expect_one_line_error(run(r + "--objects frustum --plane-masking off --json"),
                          "--plane-masking: needs --objects bvh");
    expect_one_line_error(run(r + "--objects bvh --cluster-cost 2 --json"),
                          "--cluster-cost: needs --objects bvh+backface");
    expect_one_line_error(run(r + "--meta-bv on --json"), "--meta-bv: needs --objects");
}

// A rigid BigGuy placed with a mirroring matrix (x scale -0.05): the patch clusters test the eye
// in object space, where facing is the opposite of the drawn (world-space) one, and cull what is
// drawn (~270 false culls per frame, found by this suite's probe; the CPU truth is
// tests/import/scene_object_level_test.cpp MirroredRigidInstanceIsNotBackFaceCulledWrongly).
// Fixed: ScenePoser poses mirrored instances transposed (scene_poser.h), so they are drawn
// right side out and their model-space patch clusters hold.
TEST(ObjectLevelCli, MirroredRigidInstanceHasNoFalseCulls) {
    const Summary s = verified_render("render " + test_scene("mirrored_rigid.json") +
                                          " --objects bvh+backface --size 160x90 --tess 2 --frames 3 --cull none",
                                      2, 3);
    (void)s;
}

// A rigid BigGuy at 1e5 from the origin. Drawn in float world coordinates, its control points
// were rounded by ~0.008: the object-space patch clusters culled drawn patches at the silhouette
// (26 false culls in 6 frames; kClusterRoundingRatio, scene_object_level.h, then left them out),
// and with --cull occlusion the Hi-Z test culled visible patches from 2e4 on. Drawn in a frame
// near the camera (rebase_scene), the clusters are used again (cluster tests every frame) and
// nothing is culled falsely.
TEST(ObjectLevelCli, FarSceneFilesVerify) {
    const std::string far = "render " + test_scene("far_rigid_1e5.json") + " --size 160x90 --tess 2 --frames 6";
    verified_render(far + " --objects bvh+backface", 1, 6);
    const CliRun r = run(far + " --objects bvh+backface --json");
    ASSERT_EQ(r.status, 0) << r.err;
    for (const auto& frame : nlohmann::json::parse(r.out)["frames"])
        EXPECT_GT(frame["objects"]["cluster_tests"].get<std::size_t>(), 0u) << frame.dump();
    verified_render(far + " --cull occlusion --objects frustum", 1, 6);
}

namespace patchcull::gl {
namespace {

// What --verify compares (eval_gl/reference_frame.cpp): the culled frame's ids, depth and drawn
// patches against the unculled render's ids, depth and front patches.
FrameComparison verify_frame(CullPipeline& pipeline, const RenderParams& rp,
                             std::vector<std::uint32_t>& reference_ids) {
    PatchRenderer& r = pipeline.renderer();
    const FrameCapture culled{r.read_ids(), r.read_depth(), r.read_drawn_patches()};
    RenderParams unculled = rp;
    unculled.use_cull_flags = false;
    r.render(unculled);
    FrameCapture reference{r.read_ids(), r.read_depth(), r.mark_front_patches(unculled)};
    reference_ids = reference.ids;
    return compare_frames(reference, culled);
}

// The mutation: an object level that culls a visible object (a span of the teapot's patches that
// the unculled render shows) and a visible occluder triangle. --verify's comparison must report
// the span's visible patches as false culls and the triangle's pixels must be in the reference
// only; with the honest spans (nothing culled) it reports nothing.
TEST(ObjectLevelGpu, VerifyCatchesAFalseObjectCull) {
    CullPipeline pipeline(test::context());
    const std::vector<BezierPatch> patches = test::split_teapot(1);  // 128 patches
    pipeline.set_patches(patches);
    // A box occluder beside the teapot (12 triangles), one-sided.
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    const Vec3 lo{2.2f, -0.5f, 0.0f}, hi{3.2f, 0.5f, 1.0f};
    v.reserve(8);
    for (int i = 0; i < 8; ++i) v.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
    const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& q : quads)
        for (int k : {0, 1, 2, 0, 2, 3}) idx.push_back(q[k]);
    pipeline.renderer().set_occluders(v, idx, {{0, 12}});
    RenderParams rp;
    rp.view = look_at({0.5f, -9, 4}, {0.8f, 0, 1.2f}, {0, 0, 1});
    rp.projection = perspective(0.9f, 1.0f, 0.5f, 40.0f);
    rp.width = rp.height = 96;
    rp.tess_level = 2;
    for (CullMode mode : {CullMode::none, CullMode::frustum, CullMode::all}) {
        // Honest: nothing culled by the object level; 0 false culls.
        pipeline.reset_visibility();
        PipelineParams p;
        p.frame.render = rp;
        p.frame.cull = mode;
        p.frame.timing = TimingMethod::off;
        pipeline.render_frame(p);
        std::vector<std::uint32_t> reference_ids;
        FrameComparison cmp = verify_frame(pipeline, rp, reference_ids);
        EXPECT_TRUE(cmp.false_culled.empty()) << cull_mode_name(mode);
        // The reference shows patches of [32, 64) and some box triangle.
        std::vector<std::size_t> visible;
        std::uint32_t box_triangle = ~0u;
        for (std::uint32_t id : reference_ids) {
            if (id == 0) continue;
            if (id & kIdOccluderBit)
                box_triangle = std::min(box_triangle, id & ~kIdOccluderBit);
            else if (id - 1 >= 32 && id - 1 < 64)
                visible.push_back(id - 1);
        }
        ASSERT_FALSE(visible.empty()) << "the span must be visible for the mutation to mean anything";
        ASSERT_NE(box_triangle, ~0u) << "the box must be visible";
        // Mutated: the object level culls the visible span and the visible triangle.
        pipeline.reset_visibility();
        p.object_culled = {{32, 32}};
        p.culled_occluders = {{box_triangle, 1}};
        const FrameStats stats = pipeline.render_frame(p);
        EXPECT_EQ(stats.object_culled, 32u);
        const std::vector<std::uint32_t> culled_ids = pipeline.renderer().read_ids();
        cmp = verify_frame(pipeline, rp, reference_ids);
        std::sort(visible.begin(), visible.end());
        visible.erase(std::unique(visible.begin(), visible.end()), visible.end());
        for (std::size_t pidx : visible)
            EXPECT_TRUE(std::binary_search(cmp.false_culled.begin(), cmp.false_culled.end(), pidx))
                << cull_mode_name(mode) << ": visible patch " << pidx << " culled by the object level, not reported";
        for (std::uint32_t f : cmp.false_culled)
            EXPECT_TRUE(f >= 32 && f < 64) << cull_mode_name(mode) << ": patch " << f << " reported, not culled";
        const std::uint32_t tid = kIdOccluderBit | box_triangle;
        EXPECT_NE(std::find(reference_ids.begin(), reference_ids.end(), tid), reference_ids.end());
        EXPECT_EQ(std::find(culled_ids.begin(), culled_ids.end(), tid), culled_ids.end())
            << "the culled triangle must leave the culled frame (the CLI counts it from the reference ids)";
    }
}

}  // namespace
}  // namespace patchcull::gl
