// Scenes for the renderer (patchcull/default_scene.h): the default scene's contents and placement,
// ScenePoser's world-space poses (an instance's patches are its model's patches transformed), and
// one-model scenes standing on the ground inside their camera path's view.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "patchcull/default_scene.h"
#include "patchcull/frustum.h"

using namespace patchcull;

namespace {

Bounds bounds_of(const std::vector<BezierPatch>& patches, std::size_t first, std::size_t count) {
    std::vector<Vec3> points;
    for (std::size_t p = first; p < first + count; ++p)
        for (const Vec4& c : patches[p].cp) points.push_back(cartesian(c));
    return compute_bounds(points);
}

}  // namespace

TEST(DefaultScene, SixCharactersAmongOccluders) {
    const Scene scene = make_default_scene();
    ASSERT_EQ(scene.models.size(), 2u);
    ASSERT_EQ(scene.instances.size(), 6u);
    EXPECT_EQ(scene.patch_count(), 3u * 1450u + 3u * 1292u);
    EXPECT_EQ(scene.occluder_indices.size() % 3, 0u);
    EXPECT_EQ(scene.occluder_indices.size() / 3, 2u + 3u * 12u);  // ground quad + three boxes
    for (std::uint32_t i : scene.occluder_indices) EXPECT_LT(i, scene.occluder_vertices.size());

    ScenePoser poser(scene);
    const std::vector<BezierPatch> rest = poser.pose(0);
    ASSERT_EQ(rest.size(), scene.patch_count());
    for (const SceneInstance& instance : scene.instances) {
        // At rest every character stands on the ground (its control points, which bound the
        // surface, reach down to y = 0), BigGuy 1 high, MonsterFrog 0.6.
        std::vector<BezierPatch> placed = scene.models[instance.model].rest.patches;
        for (BezierPatch& p : placed)
            for (Vec4& c : p.cp) c = instance.object_to_world * c;
        const Bounds b = bounds_of(placed, 0, placed.size());
        EXPECT_NEAR(b.min.y, 0.0f, 1e-4f);
        EXPECT_NEAR(b.max.y - b.min.y, instance.model == 0 ? 1.0f : 0.6f, 1e-4f);
    }
    // The first instance has no time offset: its pose at time 0 is its rest pose, placed.
    const SceneInstance& first = scene.instances[0];
    for (std::size_t p = 0; p < scene.models[first.model].rest.patches.size(); p += 97)
        for (int k = 0; k < kPatchPoints; ++k) {
            const Vec3 expected = cartesian(first.object_to_world * scene.models[first.model].rest.patches[p].cp[k]);
            EXPECT_NEAR(length(cartesian(rest[p].cp[k]) - expected), 0.0f, 1e-5f) << "patch " << p << " point " << k;
        }
    // Animated: a later pose moves control points, the patch count stays.
    const std::vector<BezierPatch> later = poser.pose(0.25f);
    ASSERT_EQ(later.size(), rest.size());
    std::size_t moved = 0;
    for (std::size_t p = 0; p < rest.size(); ++p) moved += rest[p].cp[5].x != later[p].cp[5].x ? 1 : 0;
    EXPECT_GT(moved, rest.size() / 2);
}

TEST(DefaultScene, CameraPathSeesTheGroupAndCutsSomePatches) {
    const Scene scene = make_default_scene();
    const std::vector<Camera> path = scene.camera_path(6, 16.0f / 9.0f);
    ASSERT_EQ(path.size(), 6u);
    EXPECT_GT(length(path[5].eye - path[0].eye), 0.1f);  // the camera moves
    ScenePoser poser(scene);
    const std::vector<BezierPatch> patches = poser.pose(0);
    const PatchBatch batch = make_batch(patches);
    for (const Camera& camera : path) {
        std::vector<std::uint8_t> culled(patches.size());
        cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(camera.view_projection(), ClipDepth::zero_to_one), culled.data());
        const auto n = static_cast<std::size_t>(std::count(culled.begin(), culled.end(), 1));
        // Most of the scene is in view, but not all of it: frustum culling has work.
        EXPECT_GT(n, 0u);
        EXPECT_LT(n, patches.size() / 2);
    }
}

TEST(DefaultScene, ModelSceneStandsOnTheGroundInView) {
    const Scene scene = make_model_scene(load_model("teapot", Scheme::acc, 0), 10.0f);
    ASSERT_EQ(scene.instances.size(), 1u);
    EXPECT_EQ(scene.patch_count(), 32u);
    ScenePoser poser(scene);
    const std::vector<BezierPatch> patches = poser.pose(1.0f);  // the teapot is rigid
    const Bounds b = bounds_of(patches, 0, patches.size());
    EXPECT_NEAR(b.min.y, 0.0f, 1e-5f);
    EXPECT_NEAR(b.max.y, 1.0f, 1e-5f);
    const PatchBatch batch = make_batch(patches);
    for (const Camera& camera : scene.camera_path(4, 1.0f)) {
        std::vector<std::uint8_t> culled(patches.size());
        cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(camera.view_projection(), ClipDepth::zero_to_one), culled.data());
        EXPECT_EQ(std::count(culled.begin(), culled.end(), 1), 0);  // the whole teapot is in view
    }
}

// Back-patch culling is applied only to closed surfaces (tools/render_support.h): the shipped
// characters are closed, the teapot is not.
TEST(DefaultScene, ShippedCharactersAreClosedTheTeapotIsNot) {
    const Scene scene = make_default_scene();
    for (const LoadedModel& m : scene.models) EXPECT_TRUE(m.closed) << m.name;
    EXPECT_FALSE(load_model("teapot", Scheme::acc, 0).closed);
}
