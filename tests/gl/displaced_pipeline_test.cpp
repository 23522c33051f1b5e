// Displaced patches in the frame (Niessner & Loop, "Patch-Based Occlusion Culling for Hardware
// Tessellation", §4.2 and §6): CullPipeline::render_frame culls displaced patches by their bound
// (DisplacedPass: caf or oobb with the cone full, acon or con) against the frustum and the
// running pipeline's Hi-Z, and undisplaced patches by the control-point tests. The strict test:
// an animated, displaced MonsterFrog with a wall in front, through a moving camera, for every
// bound and cone, has no false cull against the unculled render of each frame (per patch: the
// front set against the drawn set), and displaced patches are occlusion-culled. Also the CLI:
// `render default` (its MonsterFrogs displaced) with --verify, the JSON keys, and bad flags.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"
#include "gl_test_util.h"
#include "patchcull/gl/gl_verification.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/import/scene_poser.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

// The frog standing on the ground, displaced by a procedural map of +-10% of its height (a strong
// displacement: with a few percent, bounds shrunk to 1% of the true ranges still pass the strict
// check, see StrictCheckCatchesBoundsTooSmall), a wall hiding its lower half from the first
// cameras.
Scene displaced_frog_scene(Scheme scheme = Scheme::acc) {
    Scene scene = make_model_scene(load_model(shipped_model_path("monsterfrog.obj"), scheme, 0), 20.0f);
    scene.displacement = make_procedural_displacement(128, 0.2f);
    scene.displacement_name = "procedural";
    scene.instances[0].displaced = true;
    const CameraPath& c = scene.camera;
    const Vec3 toward{0, 0, 1};  // the path starts on +z
    const Vec3 mid = c.target + toward * (0.45f * c.distance);
    std::vector<Vec3> wall;
    for (Vec3 p : {Vec3{-2, 0, 0}, Vec3{2, 0, 0}, Vec3{2, 0.45f, 0}, Vec3{-2, 0.45f, 0}})
        wall.push_back(Vec3{p.x, p.y, mid.z});
    // An environment object of its own (Scene::environment tiles occluder_indices), two-sided:
    // a single quad is no closed solid.
    add_environment_object(scene, "wall", wall, {0, 1, 2, 0, 2, 3}, false);
    return scene;
}

// range_scale < 1: bounds deliberately too small (the mutation the strict check must catch); the
// drawn surface keeps the map's full displacement (the TES displaces every patch with margin > 0).
PatchAttributes attributes_of(const ScenePoser& poser, float range_scale = 1.0f) {
    PatchAttributes a;
    a.tangent_index = poser.tangent_index();
    a.tangents = poser.tangents();
    a.depth = poser.depth();
    a.texcoords = poser.texcoords();
    a.displacement_ranges = poser.displacement_ranges();
    for (DisplacementRange& r : a.displacement_ranges) {
        r.d_min *= range_scale;
        r.d_max *= range_scale;
    }
    return a;
}

RenderParams params_of(const Camera& camera) {
    RenderParams p;
    p.view = camera.view();
    p.projection = camera.projection();
    p.width = p.height = 96;
    p.tess_level = 4;
    p.discard_back_facing = true;  // the frog is a closed solid; its displaced patches stay two-sided
    return p;
}

// One pipeline frame, then the unculled render of the same frame: the false culls (per patch, the
// front set against the drawn set).
std::vector<std::uint32_t> false_culls_of_frame(CullPipeline& pipeline, const PipelineParams& pp, FrameStats& stats) {
    PatchRenderer& r = pipeline.renderer();
    stats = pipeline.render_frame(pp);
    const FrameCapture culled{r.read_ids(), r.read_depth(), r.read_drawn_patches()};
    RenderParams unculled = pp.frame.render;
    unculled.use_cull_flags = false;
    r.render(unculled);
    const FrameCapture reference{r.read_ids(), r.read_depth(), r.mark_front_patches(unculled)};
    return compare_frames(reference, culled).false_culled;
}

}  // namespace

TEST(DisplacedPipeline, StrictForEveryBoundAndConeThroughAnAnimatedSequence) {
    const Scene scene = displaced_frog_scene();
    ASSERT_TRUE(scene.models[0].closed);
    const std::vector<Camera> cameras = scene.camera_path(4, 1.0f);
    CullPipeline pipeline(test::context());
    PatchRenderer& r = pipeline.renderer();
    r.set_displacement_map(scene.displacement);
    r.set_occluders(scene.occluder_vertices, scene.occluder_indices);
    std::size_t displaced_occluded_all = 0;
    for (DisplacedBoundKind bound : {DisplacedBoundKind::caf, DisplacedBoundKind::oobb}) {
        for (NormalConeKind cone : {NormalConeKind::full, NormalConeKind::acon, NormalConeKind::con}) {
            const std::string combo = std::string(displaced_bound_name(bound)) + "/" + normal_cone_name(cone);
            ScenePoser poser(scene);
            pipeline.set_patches(poser.pose(0), attributes_of(poser));
            std::size_t displaced_occluded = 0, frustum = 0;
            for (std::size_t f = 0; f < cameras.size(); ++f) {
                if (f > 0) {
                    const std::vector<BezierPatch>& posed = poser.pose(0.25f * static_cast<float>(f));
                    pipeline.update_patches(posed, attributes_of(poser));
                }
                PipelineParams pp;
                pp.frame.render = params_of(cameras[f]);
                pp.frame.cull = CullMode::all;
                pp.bound = bound;
                pp.cone = cone;
                FrameStats s;
                const std::vector<std::uint32_t> false_culled = false_culls_of_frame(pipeline, pp, s);
                EXPECT_TRUE(false_culled.empty())
                    << combo << " frame " << f << ": " << false_culled.size() << " false culls, first patch "
                    << (false_culled.empty() ? 0u : false_culled[0]);
                EXPECT_EQ(s.backpatch_culled, 0u) << combo << ": every patch of the frog is displaced";
                EXPECT_LE(s.displaced_occlusion_culled, s.occlusion_culled);
                displaced_occluded += s.displaced_occlusion_culled;
                frustum += s.frustum_culled;
            }
            std::printf("[ info     ] %s: %zu displaced patches occlusion-culled, %zu frustum-culled over %zu frames\n",
                        combo.c_str(), displaced_occluded, frustum, cameras.size());
            displaced_occluded_all += displaced_occluded;
        }
    }
    EXPECT_GT(displaced_occluded_all, 100u);  // the wall and the frog itself hide displaced patches
}

TEST(DisplacedPipeline, StrictCheckCatchesBoundsTooSmall) {
    // The same sequence with every range shrunk to 1%: the bounds no longer hold the displaced
    // surface, and the comparison with the unculled render must find the patches culled wrongly.
    const Scene scene = displaced_frog_scene();
    const std::vector<Camera> cameras = scene.camera_path(4, 1.0f);
    CullPipeline pipeline(test::context());
    pipeline.renderer().set_displacement_map(scene.displacement);
    pipeline.renderer().set_occluders(scene.occluder_vertices, scene.occluder_indices);
    ScenePoser poser(scene);
    pipeline.set_patches(poser.pose(0), attributes_of(poser, 0.01f));
    std::size_t false_culls = 0;
    for (std::size_t f = 0; f < cameras.size(); ++f) {
        if (f > 0) pipeline.update_patches(poser.pose(0.25f * static_cast<float>(f)), attributes_of(poser, 0.01f));
        PipelineParams pp;
        pp.frame.render = params_of(cameras[f]);
        FrameStats s;
        false_culls += false_culls_of_frame(pipeline, pp, s).size();
    }
    EXPECT_GT(false_culls, 0u) << "bounds 100x too small went unnoticed: the strict test would be vacuous";
}

TEST(DisplacedPipeline, StrictWithOsdPatchesOfMixedDepth) {
    // OpenSubdiv's adaptive patches (several refinement depths, watertight by the depth scale of
    // the tessellation level), displaced, animated: caf/acon, every frame without a false cull.
    const Scene scene = displaced_frog_scene(Scheme::osd);
    const std::vector<Camera> cameras = scene.camera_path(3, 1.0f);
    CullPipeline pipeline(test::context());
    PatchRenderer& r = pipeline.renderer();
    r.set_displacement_map(scene.displacement);
    r.set_occluders(scene.occluder_vertices, scene.occluder_indices);
    ScenePoser poser(scene);
    pipeline.set_patches(poser.pose(0), attributes_of(poser));
    std::size_t displaced_occluded = 0;
    for (std::size_t f = 0; f < cameras.size(); ++f) {
        if (f > 0) pipeline.update_patches(poser.pose(0.25f * static_cast<float>(f)), attributes_of(poser));
        PipelineParams pp;
        pp.frame.render = params_of(cameras[f]);
        pp.frame.render.tess_level = 2;  // times 2^(D - depth) per patch
        FrameStats s;
        EXPECT_TRUE(false_culls_of_frame(pipeline, pp, s).empty()) << "osd frame " << f;
        displaced_occluded += s.displaced_occlusion_culled;
    }
    EXPECT_GT(displaced_occluded, 100u);
}

TEST(DisplacedPipeline, UndisplacedObjectsOfADisplacedSceneKeepEveryTest) {
    // The default scene: BigGuys plain (back-patch culled, one-sided), MonsterFrogs displaced
    // (occlusion-culled by their bounds, never back-patch culled), through the CLI with --verify.
    using namespace patchcull::cli_test;
    const CliRun r = run("render default --size 96x54 --tess 2 --frames 3 --verify --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["displace"], "procedural");
    EXPECT_EQ(j["bound"], "caf");
    EXPECT_EQ(j["cone"], "acon");
    EXPECT_GT(j["displaced_patches"].get<std::size_t>(), 3000u);  // the three frogs
    EXPECT_LT(j["displaced_patches"].get<std::size_t>(), j["patches"].get<std::size_t>());
    EXPECT_GT(j["displace_scale"].get<double>(), 0.0);
    std::size_t displaced_occluded = 0, back = 0;
    for (const auto& f : j["frames"]) {
        EXPECT_LE(f["displaced_occlusion_culled"].get<std::size_t>(), f["occlusion_culled"].get<std::size_t>());
        displaced_occluded += f["displaced_occlusion_culled"].get<std::size_t>();
        back += f["backpatch_culled"].get<std::size_t>();
        EXPECT_EQ(f["false_culls"], 0);
    }
    EXPECT_GT(displaced_occluded, 0u);
    EXPECT_GT(back, 0u);
    EXPECT_EQ(j["false_culls"], 0);
    // --displace none: nothing displaced; oobb and con accepted.
    const CliRun plain = run("render default --size 64x36 --tess 1 --frames 1 --displace none --json");
    ASSERT_EQ(plain.status, 0) << plain.err;
    EXPECT_EQ(nlohmann::json::parse(plain.out)["displaced_patches"], 0);
    const CliRun other = run("render default --size 64x36 --tess 1 --frames 2 --bound oobb --cone con --verify --json");
    ASSERT_EQ(other.status, 0) << other.err;
    EXPECT_EQ(nlohmann::json::parse(other.out)["false_culls"], 0);
}

TEST(DisplacedPipeline, BadDisplacementFlagsAreOneLineErrors) {
    using namespace patchcull::cli_test;
    const std::string base = "render default --size 32x32 --frames 1 ";
    expect_one_line_error(run(base + "--displace-scale 0.1"), "--displace-scale");
    expect_one_line_error(run(base + "--displace procedural --displace-scale 2"), "--displace-scale");
    expect_one_line_error(run(base + "--displace procedural --displace-scale 0"), "--displace-scale");
    expect_one_line_error(run(base + "--bound box"), "--bound");
    expect_one_line_error(run(base + "--cone wide"), "--cone");
    expect_one_line_error(run(base + "--displace /nonexistent/height.png"), "/nonexistent/height.png");
    expect_one_line_error(run(base + "--displace " + model("bigguy.obj")), "bigguy.obj");
}
