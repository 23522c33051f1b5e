// scene_occlusion.h's CPU parts: which environment objects are box occluders, span merging,
// SceneTightBounds (every patch box inside its instance's selection), and bad setups.
#include <gtest/gtest.h>

#include <random>

#include "patchcull/core/error.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_occlusion.h"
#include "patchcull/import/scene_poser.h"

namespace patchcull {
namespace {

bool contains(const Bounds& outer, const Bounds& inner) {
    return outer.min.x <= inner.min.x && outer.min.y <= inner.min.y && outer.min.z <= inner.min.z &&
           outer.max.x >= inner.max.x && outer.max.y >= inner.max.y && outer.max.z >= inner.max.z;
}

TEST(SceneOcclusion, BoxOccludersAreTheClosedBoxes) {
    CityParams p;
    p.blocks_x = 2;
    p.blocks_z = 3;
    p.characters = 0;
    const Scene city = make_city_scene(Scheme::acc, p);
    const std::vector<std::size_t> boxes = box_environment_objects(city);
    ASSERT_EQ(boxes.size(), 6u);  // the buildings, not the ground quad
    for (std::size_t e : boxes)
        EXPECT_EQ(city.environment[e].name.rfind("building#", 0), 0u) << city.environment[e].name;

    Scene scene;
    add_environment_box(scene, "box", {0, 0, 0}, {1, 2, 3});
    // A box without its top: its two top triangles left out.
    std::vector<Vec3> v;
    v.reserve(8);
    for (int c = 0; c < 8; ++c) v.push_back({(c & 4) ? 1.0f : 0.0f, (c & 2) ? 1.0f : 0.0f, (c & 1) ? 1.0f : 0.0f});
    add_environment_object(scene, "open", v,
                           {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3},
                           true);
    // A flat box and a quad.
    add_environment_box(scene, "flat", {0, 0, 0}, {1, 0, 1});
    add_environment_object(scene, "quad", {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}, {0, 1, 2, 0, 2, 3}, true);
    // 12 triangles on the corners but one cutting through the inside.
    add_environment_object(scene, "diagonal", v, {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1,
                                                  2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 0, 7, 3},
                           true);
    const std::vector<std::size_t> found = box_environment_objects(scene);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(scene.environment[found[0]].name, "box");
}

TEST(SceneOcclusion, MergeSpansSortsAndJoins) {
    std::vector<IndexSpan> spans = {{10, 5}, {0, 3}, {3, 2}, {12, 10}, {40, 0}, {30, 1}};
    merge_spans(spans);
    ASSERT_EQ(spans.size(), 3u);
    EXPECT_EQ(spans[0].first, 0u);
    EXPECT_EQ(spans[0].count, 5u);
    EXPECT_EQ(spans[1].first, 10u);
    EXPECT_EQ(spans[1].count, 12u);
    EXPECT_EQ(spans[2].first, 30u);
    EXPECT_EQ(spans[2].count, 1u);
}

TEST(SceneOcclusion, TightBoundsHoldEveryPatchOfEveryPose) {
    CityParams p;
    p.blocks_x = 2;
    p.blocks_z = 2;
    p.characters = 4;
    const Scene scene = make_city_scene(Scheme::acc, p);
    ScenePoser poser(scene);
    SceneTightBounds tight(scene, poser.pose(0), poser.displacement_ranges());
    std::size_t first = 0;
    for (float t : {0.0f, 0.4f, 1.3f}) {
        const std::vector<BezierPatch>& pose = poser.pose(t);
        for (float sigma : {1.0f, 1.4f, 4.0f}) {
            tight.update(pose, poser.displacement_ranges(), sigma, 16);
            ASSERT_EQ(tight.first().size(), scene.instances.size() + 1);
            first = 0;
            for (std::size_t i = 0; i < scene.instances.size(); ++i) {
                const std::size_t count = scene.models[scene.instances[i].model].rest.patches.size();
                ASSERT_GT(tight.first()[i + 1], tight.first()[i]);
                EXPECT_LE(tight.first()[i + 1] - tight.first()[i], 16u);
                for (std::size_t q = first; q < first + count; ++q) {
                    Bounds b{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
                    for (const Vec4& c : pose[q].cp) {
                        const Vec3 x = cartesian(c);
                        b.min = {std::min(b.min.x, x.x), std::min(b.min.y, x.y), std::min(b.min.z, x.z)};
                        b.max = {std::max(b.max.x, x.x), std::max(b.max.y, x.y), std::max(b.max.z, x.z)};
                    }
                    bool held = false;
                    for (std::uint32_t k = tight.first()[i]; k < tight.first()[i + 1] && !held; ++k)
                        held = contains(tight.boxes()[k], b);
                    EXPECT_TRUE(held) << "instance " << i << " patch " << q << " sigma " << sigma;
                }
                first += count;
            }
        }
    }
}

TEST(SceneOcclusion, BadSetupsAreErrors) {
    CityParams p;
    p.blocks_x = 1;
    p.blocks_z = 1;
    p.characters = 0;
    Scene city = make_city_scene(Scheme::acc, p);
    SceneObjectLevel level(city);
    EXPECT_THROW(SceneOcclusion(city, level, SceneOcclusionMethod::portals), Error);  // no cells
    Scene empty;
    add_environment_object(empty, "quad", {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}}, {0, 1, 2}, true);
    SceneObjectLevel empty_level(empty);
    EXPECT_THROW(SceneOcclusion(empty, empty_level, SceneOcclusionMethod::horizon), Error);  // no boxes
    SceneOcclusionMethod m = SceneOcclusionMethod::horizon;
    EXPECT_TRUE(parse_scene_occlusion_method("portals", m));
    EXPECT_EQ(m, SceneOcclusionMethod::portals);
    EXPECT_FALSE(parse_scene_occlusion_method("portal", m));
}

}  // namespace
}  // namespace patchcull
