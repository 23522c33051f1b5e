// Mirrored instances drawn right side out (scene_poser.h, ScenePoser): a
// closed model placed with a mirroring transform is posed with its patches transposed, so that
// du x dv, which the one-sided fragment test keeps where it faces the eye (README "What
// contributes a pixel"), points out of the mirrored solid. On the GPU: the id buffer of a
// mirrored BigGuy, seen by a camera on the mirror plane, is the unmirrored BigGuy's id buffer
// mirrored in x (the same patches at the mirrored pixels, up to a few pixels where the transposed
// tessellation differs), while the naive mirror image (the patches transformed, not transposed)
// shows its inside. Through the CLI: the mirrored_rigid scene verified with the object level's
// patch clusters (Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for Hardware
// Tessellation", tangent control planes, used for rigid instances) and every patch-level pass
// has 0 false culls. llvmpipe, tiny sizes, seconds.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"
#include "gl_test_util.h"
#include "patchcull/gl/gl_renderer.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/import/scene_poser.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

constexpr int kSize = 128;

struct Capture {
    std::vector<std::uint32_t> ids;
    std::size_t covered = 0;
};

Capture render_scene(const Scene& scene, const std::vector<BezierPatch>* override_patches = nullptr) {
    ScenePoser poser(scene);
    const std::vector<BezierPatch>& posed = poser.pose(0);
    PatchAttributes a;
    a.tangent_index = poser.tangent_index();
    a.tangents = poser.tangents();
    a.depth = poser.depth();
    PatchRenderer r(test::context());
    r.set_patches(override_patches ? *override_patches : posed, a);
    Camera cam;
    cam.eye = {0, 0.6f, 2.2f};  // on the mirror plane x = 0
    cam.target = {0, 0.5f, 0};
    cam.fovy_radians = 0.6f;
    cam.aspect = 1;
    cam.z_near = 0.5f;
    cam.z_far = 10;
    RenderParams rp;
    rp.view = cam.view();
    rp.projection = cam.projection();
    rp.width = rp.height = kSize;
    rp.tess_level = 4;
    rp.discard_back_facing = true;
    r.render(rp);
    Capture c;
    c.ids = r.read_ids();
    for (std::uint32_t id : c.ids) c.covered += id != 0 ? 1 : 0;
    return c;
}

struct Agreement {
    std::size_t coverage_mismatch = 0;  ///< pixels covered in one image and not at the mirrored pixel of the other
    std::size_t same_patch = 0;         ///< covered pixels whose mirrored pixel shows the same patch
};

Agreement compare_mirrored(const Capture& a, const Capture& b) {
    Agreement g;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const std::uint32_t ia = a.ids[static_cast<std::size_t>(y) * kSize + x];
            const std::uint32_t ib = b.ids[static_cast<std::size_t>(y) * kSize + (kSize - 1 - x)];
            if ((ia != 0) != (ib != 0)) ++g.coverage_mismatch;
            if (ia != 0 && ia == ib) ++g.same_patch;
        }
    return g;
}

Scene bigguy_scene() {
    Scene scene = make_model_scene(load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0));
    scene.instances[0].deforms = false;
    return scene;
}

}  // namespace

TEST(MirroredInstance, IdBufferIsTheUnmirroredOneMirroredInX) {
    const Scene plain = bigguy_scene();
    ASSERT_TRUE(plain.models[0].closed);
    Scene mirrored = plain;
    Mat4 mirror;
    mirror.at(0, 0) = -1;
    mirrored.instances[0].object_to_world = mirror * plain.instances[0].object_to_world;
    ASSERT_TRUE(instance_mirrors(mirrored.instances[0]));

    const Capture a = render_scene(plain);
    const Capture b = render_scene(mirrored);
    ASSERT_GT(a.covered, static_cast<std::size_t>(kSize * kSize / 20)) << "BigGuy should fill part of the view";
    const Agreement g = compare_mirrored(a, b);
    // Coverage: the silhouettes agree up to a few pixels (the transposed patch is tessellated
    // along the other parameter: its triangles' edges differ from the mirrored ones by a fraction
    // of a pixel at this size).
    EXPECT_LE(g.coverage_mismatch, a.covered / 50) << "covered " << a.covered << ", mirrored " << b.covered;
    // The same patches at the mirrored pixels: the front of the mirrored BigGuy, not its inside.
    EXPECT_GE(g.same_patch, a.covered * 95 / 100) << "covered " << a.covered;

    // The check can fail: the naive mirror image (transformed, not transposed) is drawn inside
    // out, showing the far side's patches (or nothing) at most pixels.
    std::vector<BezierPatch> naive = mirrored.models[0].rest.patches;
    for (BezierPatch& p : naive)
        for (Vec4& c : p.cp) c = mirrored.instances[0].object_to_world * c;
    Capture n = render_scene(mirrored, &naive);
    const Agreement gn = compare_mirrored(a, n);
    EXPECT_LT(gn.same_patch, a.covered / 2) << "the naive mirror image should show other patches";
    std::printf("[ info     ] covered %zu, mirrored %zu: coverage mismatch %zu, same patch %zu (naive mirror: %zu)\n",
                a.covered, b.covered, g.coverage_mismatch, g.same_patch, gn.same_patch);
}

// The probe's scene (a rigid mirrored BigGuy) through the CLI, with patch clusters and every
// patch-level test: 0 false culls against the unculled render, frame by frame; the clusters do
// cull some of the mirrored instance's patches (the instance is clustered again).
TEST(MirroredInstance, MirroredRigidSceneVerifiesWithClusters) {
    using namespace patchcull::cli_test;
    const std::string scene = std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/scenes/mirrored_rigid.json";
    for (const char* cull : {"all", "none"}) {
        const std::string args = "render " + scene + " --cull " + cull +
                                 " --objects bvh+backface --size 160x90 --tess 2 --frames 3 --verify --json";
        const CliRun r = run(args);
        ASSERT_EQ(r.status, 0) << args << ": " << r.err;
        const auto j = nlohmann::json::parse(r.out);
        EXPECT_EQ(j["verified"], true) << args;
        EXPECT_EQ(j["false_culls"], 0) << args;
        ASSERT_EQ(j["frames"].size(), 3u) << args;
        std::size_t backface_patches = 0;
        for (const auto& frame : j["frames"]) {
            EXPECT_EQ(frame["false_culls"], 0) << args << ", frame " << frame["frame"].dump();
            backface_patches += frame["objects"]["backface_patches_culled"].get<std::size_t>();
        }
        EXPECT_GT(backface_patches, 0u) << args << ": the mirrored instance's clusters culled nothing";
    }
}
