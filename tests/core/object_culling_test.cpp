// ObjectCuller (patchcull/objects/object_culling.h): the order and bookkeeping of the object level, and
// the CPU patch level after it (cull_frustum_after_objects). The tests' geometry answers are
// checked against ground truth in tests/import/scene_object_level_test.cpp.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/objects/object_culling.h"

namespace patchcull {
namespace {

Mat4 test_view_projection() {
    return perspective(1.0f, 1.0f, 0.1f, 100.0f) * look_at({0, 0, 10}, {0, 0, 0}, {0, 1, 0});
}

Bounds box_at(Vec3 c, float r) { return {c - Vec3{r, r, r}, c + Vec3{r, r, r}}; }

TEST(ObjectCuller, MethodsCullTheObjectsOutsideAndListTheirSpans) {
    // Three patch objects and one triangle object; objects 1 (behind the eye) and 3 (far left) are out.
    ObjectCuller culler({{"a", false, {0, 10}}, {"b", false, {10, 5}}, {"c", false, {15, 7}}, {"t", true, {0, 12}}});
    const std::vector<Bounds> boxes = {box_at({0, 0, 0}, 1), box_at({0, 0, 20}, 1), box_at({1, 0, -3}, 1),
                                       box_at({-200, 0, 0}, 1)};
    ObjectFrame frame;
    frame.world_to_clip = test_view_projection();
    frame.eye = {0, 0, 10};
    frame.boxes = boxes.data();
    for (ObjectCullMethod m : {ObjectCullMethod::frustum, ObjectCullMethod::bvh, ObjectCullMethod::bvh_backface}) {
        for (int repeat = 0; repeat < 3; ++repeat) {  // coherence state carried over frames
            ObjectCullOptions options;
            options.method = m;
            const ObjectCullResult& r = culler.cull(frame, options);
            ASSERT_EQ(r.verdicts.size(), 4u);
            EXPECT_EQ(r.verdicts[0], ObjectVerdict::visible);
            EXPECT_EQ(r.verdicts[1], ObjectVerdict::frustum);
            EXPECT_EQ(r.verdicts[2], ObjectVerdict::visible);
            EXPECT_EQ(r.verdicts[3], ObjectVerdict::frustum);
            ASSERT_EQ(r.culled_patches.size(), 1u);
            EXPECT_EQ(r.culled_patches[0].first, 10u);
            EXPECT_EQ(r.culled_patches[0].count, 5u);
            ASSERT_EQ(r.culled_triangles.size(), 1u);
            EXPECT_EQ(r.culled_triangles[0].count, 12u);
            EXPECT_EQ(r.stats.frustum_culled, 2u);
            EXPECT_EQ(r.stats.patches_culled, 5u);
            EXPECT_GT(r.stats.plane_tests, 0u);
        }
    }
    ObjectCullOptions none;
    const ObjectCullResult& r = culler.cull(frame, none);
    EXPECT_TRUE(r.culled_patches.empty());
    EXPECT_EQ(r.stats.total, 4u);
    EXPECT_EQ(r.stats.plane_tests, 0u);
}

TEST(ObjectCuller, FlatAndBvhAgreeOnRandomScenes) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> pos(-40, 40), size(0.01f, 6);
    for (int scene = 0; scene < 20; ++scene) {
        const std::size_t n = 1 + rng() % 300;
        std::vector<CullableObject> objects;
        std::vector<Bounds> boxes;
        for (std::size_t i = 0; i < n; ++i) {
            objects.push_back({"o", false, {i * 4, 4}});
            boxes.push_back(box_at({pos(rng), pos(rng), pos(rng)}, size(rng)));
        }
        ObjectCuller flat(objects), bvh(objects);
        for (int f = 0; f < 5; ++f) {
            ObjectFrame frame;
            frame.eye = {pos(rng), pos(rng), pos(rng)};
            frame.world_to_clip =
                perspective(0.9f, 1.5f, 0.1f, 60.0f) * look_at(frame.eye, {pos(rng), pos(rng), pos(rng)}, {0, 1, 0});
            frame.boxes = boxes.data();
            for (Bounds& b : boxes) b.min.x += 0.3f, b.max.x += 0.3f;  // motion: the BVH refits
            ObjectCullOptions a, b;
            a.method = ObjectCullMethod::frustum;
            b.method = ObjectCullMethod::bvh;
            b.plane_masking = (f % 2) == 0;
            const std::vector<ObjectVerdict> va = flat.cull(frame, a).verdicts;
            const std::vector<ObjectVerdict> vb = bvh.cull(frame, b).verdicts;
            EXPECT_EQ(va, vb) << "scene " << scene << " frame " << f;
        }
    }
}

TEST(ObjectCuller, RefusesOverlappingObjectsAndClustersOutsideTheObject) {
    EXPECT_THROW(ObjectCuller({{"a", false, {0, 10}}, {"b", false, {9, 5}}}), Error);
    EXPECT_NO_THROW(ObjectCuller({{"a", false, {0, 10}}, {"t", true, {5, 5}}}));  // other kind
    ObjectCuller culler({{"a", true, {0, 2}}});
    const std::vector<Vec3> v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    ClusterHierarchy three = build_triangle_clusters(v, {0, 1, 2, 1, 3, 2, 0, 2, 1}, 0.0, 1);
    EXPECT_THROW(culler.set_clusters(0, three, false), Error);  // 3 triangles, the object has 2
    EXPECT_THROW(culler.set_clusters(1, three, false), Error);
}

TEST(ObjectCuller, DetailCullingTakesSmallObjectsOnlyWhenAsked) {
    ObjectCuller culler({{"near", false, {0, 1}}, {"tiny", false, {1, 1}}});
    const std::vector<Bounds> boxes = {box_at({0, 0, 0}, 1), box_at({0.5f, 0, -50}, 0.001f)};
    ObjectFrame frame;
    frame.world_to_clip = test_view_projection();
    frame.eye = {0, 0, 10};
    frame.boxes = boxes.data();
    frame.pixel_scale = projection_pixel_scale(1.0f, 720);
    ObjectCullOptions options;
    options.method = ObjectCullMethod::bvh;
    EXPECT_EQ(culler.cull(frame, options).stats.detail_culled, 0u);
    options.detail_min_pixels = 1;
    const ObjectCullResult& r = culler.cull(frame, options);
    EXPECT_EQ(r.verdicts[0], ObjectVerdict::visible);
    EXPECT_EQ(r.verdicts[1], ObjectVerdict::detail);
    EXPECT_EQ(r.stats.detail_culled, 1u);
    EXPECT_EQ(r.stats.patches_culled, 1u);
}

TEST(ObjectCuller, CpuFrustumKernelSkipsCulledSpans) {
    // Ten unit patches at the origin (in view): the kernel culls none; spans 2..4 and 7 are culled
    // by the object level, so it tests 6 patches and reports 4 culled.
    std::vector<BezierPatch> patches(10);
    for (BezierPatch& p : patches)
        for (int k = 0; k < kPatchPoints; ++k) {
            const int col = k % 4, row = k / 4;
            p.cp[k] = {float(col) * 0.1f, float(row) * 0.1f, 0, 1};
        }
    const PatchBatch batch = make_batch(patches);
    ObjectCullResult result;
    result.culled_patches = {{2, 3}, {7, 1}};
    std::vector<std::uint8_t> culled(10, 9);
    const std::size_t tested =
        cull_frustum_after_objects(result, batch.view(), nullptr,
                                   make_frustum_planes(test_view_projection(), ClipDepth::zero_to_one), culled.data());
    EXPECT_EQ(tested, 6u);
    EXPECT_EQ(culled, (std::vector<std::uint8_t>{0, 0, 1, 1, 1, 0, 0, 1, 0, 0}));
    std::vector<std::pair<std::size_t, std::size_t>> visited;
    for_each_active_span(result.culled_patches, 10, [&](std::size_t f, std::size_t c) { visited.push_back({f, c}); });
    EXPECT_EQ(visited, (std::vector<std::pair<std::size_t, std::size_t>>{{0, 2}, {5, 2}, {8, 2}}));
}

}  // namespace
}  // namespace patchcull
