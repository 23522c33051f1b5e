// Scenes for the renderer (patchcull/default_scene.h): the default scene's contents and placement,
// ScenePoser's world-space poses (an instance's patches are its model's patches transformed), and
// one-model scenes standing on the ground inside their camera path's view.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "patchcull/default_scene.h"
#include "patchcull/error.h"
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

TEST(DefaultScene, NamesAndEnvironmentObjects) {
    const Scene scene = make_default_scene();
    const char* const names[] = {"bigguy#0", "monsterfrog#0", "bigguy#1", "monsterfrog#1", "bigguy#2", "monsterfrog#2"};
    ASSERT_EQ(scene.instances.size(), 6u);
    for (std::size_t i = 0; i < 6; ++i) {
        EXPECT_EQ(scene.instances[i].name, names[i]);
        EXPECT_TRUE(scene.instances[i].deforms);
        EXPECT_EQ(length(scene.instances[i].velocity), 0.0f);
    }
    ASSERT_EQ(scene.environment.size(), 4u);
    const char* const env[] = {"ground", "wall", "pillar#0", "pillar#1"};
    std::uint32_t next = 0;
    for (std::size_t e = 0; e < 4; ++e) {
        const EnvironmentObject& o = scene.environment[e];
        EXPECT_EQ(o.name, env[e]);
        EXPECT_TRUE(o.one_sided);
        EXPECT_EQ(o.first_triangle, next);
        EXPECT_EQ(o.triangle_count, e == 0 ? 2u : 12u);
        next += o.triangle_count;
        // Counter-clockwise seen from outside: the signed volume is the box's (the ground's
        // triangles face +y).
        double volume = 0;
        Vec3 lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
        for (std::uint32_t t = o.first_triangle; t < next; ++t) {
            const Vec3 a = scene.occluder_vertices[scene.occluder_indices[3 * t]];
            const Vec3 b = scene.occluder_vertices[scene.occluder_indices[3 * t + 1]];
            const Vec3 c = scene.occluder_vertices[scene.occluder_indices[3 * t + 2]];
            if (e == 0) {
                EXPECT_GT(cross(b - a, c - a).y, 0.0f);
            }
            volume += dot(a, cross(b, c)) / 6.0;
            for (Vec3 p : {a, b, c})
                lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)},
                hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
        }
        if (e > 0) {
            const double box = double(hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z);
            EXPECT_NEAR(volume, box, 1e-5 * box) << o.name;
        }
    }
    EXPECT_EQ(next * 3, scene.occluder_indices.size());
    // The model scene names its instance and ground.
    const Scene teapot = make_model_scene(load_model("teapot", Scheme::acc, 0));
    EXPECT_EQ(teapot.instances[0].name, "teapot#0");
    ASSERT_EQ(teapot.environment.size(), 1u);
    EXPECT_EQ(teapot.environment[0].name, "ground");
}

// instance_to_world moves by velocity * (t + time_offset) and keeps the linear part.
TEST(DefaultScene, InstanceToWorldIsTheRigidMotion) {
    SceneInstance instance;
    instance.object_to_world.at(0, 0) = 2;
    instance.object_to_world.at(1, 3) = 5;
    instance.time_offset = 0.5f;
    instance.velocity = {1, 0, -2};
    const Mat4 m = instance_to_world(instance, 1.5f);
    EXPECT_EQ(m.at(0, 0), 2.0f);
    EXPECT_EQ(m.at(0, 3), 2.0f);
    EXPECT_EQ(m.at(1, 3), 5.0f);
    EXPECT_EQ(m.at(2, 3), -4.0f);
    EXPECT_EQ(m.at(3, 3), 1.0f);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(m.at(r, c), instance.object_to_world.at(r, c));
    instance.velocity = {};
    const Mat4 still = instance_to_world(instance, 7);
    for (int k = 0; k < 16; ++k) EXPECT_EQ(still.m[k], instance.object_to_world.m[k]);
}

// pose() shares one evaluation per (model, effective time): its output equals evaluating every
// instance on its own, bit for bit (patches, tangents, depth), with rigid instances at rest and
// moving ones moved.
TEST(DefaultScene, PoseSharesFramesAndMatchesPerInstanceEvaluation) {
    Scene scene = make_default_scene();
    // Copies sharing phases, a rigid one, a moving one.
    scene.instances[1].time_offset = scene.instances[0].time_offset;
    scene.instances[2].time_offset = scene.instances[0].time_offset;
    scene.instances[3].deforms = false;
    scene.instances[4].velocity = {0.5f, 0, -0.25f};
    scene.instances.push_back(scene.instances[0]);
    scene.instances.back().name = "bigguy#3";
    scene.instances.back().object_to_world.at(0, 3) += 3;
    ScenePoser poser(scene);
    for (float t : {0.0f, 0.4f, 1.3f}) {
        const std::vector<BezierPatch>& patches = poser.pose(t);
        ASSERT_EQ(patches.size(), scene.patch_count());
        std::size_t next = 0;
        std::vector<Vec3> positions;
        PatchFrame frame;
        for (const SceneInstance& instance : scene.instances) {
            const LoadedModel& model = scene.models[instance.model];
            const PatchFrame* source = &model.rest;
            if (instance.deforms) {
                animate(model.subdiv->mesh.positions, t + instance.time_offset, scene.animation, positions);
                evaluate_frame(model, positions, frame);
                source = &frame;
            }
            const Mat4 m = instance_to_world(instance, t);
            for (std::size_t p = 0; p < source->patches.size(); ++p, ++next) {
                for (int k = 0; k < kPatchPoints; ++k) {
                    const Vec4 expected = m * source->patches[p].cp[k];
                    ASSERT_EQ(patches[next].cp[k].x, expected.x) << instance.name << " patch " << p;
                    ASSERT_EQ(patches[next].cp[k].y, expected.y);
                    ASSERT_EQ(patches[next].cp[k].z, expected.z);
                    ASSERT_EQ(patches[next].cp[k].w, expected.w);
                }
                ASSERT_EQ(poser.depth()[next], source->info[p].depth);
                const std::int32_t ti = source->info[p].tangent_index;
                ASSERT_EQ(poser.tangent_index()[next] >= 0, ti >= 0);
                if (ti >= 0) {
                    const Vec3 d = source->tangents[static_cast<std::size_t>(ti)].du[3];
                    const Vec4 e = m * Vec4{d.x, d.y, d.z, 0};
                    const Vec3 got = poser.tangents()[static_cast<std::size_t>(poser.tangent_index()[next])].du[3];
                    ASSERT_EQ(got.x, e.x);
                    ASSERT_EQ(got.z, e.z);
                }
            }
        }
        // Tangent entries are in patch order, one per patch that has one.
        std::int32_t last = -1;
        for (std::int32_t ti : poser.tangent_index())
            if (ti >= 0) {
                ASSERT_EQ(ti, ++last);
            }
        ASSERT_EQ(static_cast<std::size_t>(last + 1), poser.tangents().size());
    }
}

// The public environment helpers keep the tiling and check their input.
TEST(DefaultScene, AddEnvironmentObjects) {
    Scene scene = make_model_scene(load_model("teapot", Scheme::acc, 0));
    add_environment_box(scene, "crate", {1, 0, 1}, {2, 1, 2});
    add_environment_object(scene, "sign", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, false);
    ASSERT_EQ(scene.environment.size(), 3u);
    EXPECT_EQ(scene.environment[1].first_triangle, 2u);
    EXPECT_EQ(scene.environment[1].triangle_count, 12u);
    EXPECT_TRUE(scene.environment[1].one_sided);
    EXPECT_EQ(scene.environment[2].first_triangle, 14u);
    EXPECT_FALSE(scene.environment[2].one_sided);
    EXPECT_EQ(scene.occluder_indices.size(), 15u * 3u);
    EXPECT_EQ(scene.occluder_indices.back(), static_cast<std::uint32_t>(scene.occluder_vertices.size() - 1));
    EXPECT_THROW(add_environment_object(scene, "bad", {{0, 0, 0}}, {0, 0, 1}, false), Error);
    EXPECT_THROW(add_environment_object(scene, "bad", {{0, 0, 0}}, {0, 0}, false), Error);
    EXPECT_EQ(scene.environment.size(), 3u);
}
