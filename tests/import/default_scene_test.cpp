// Scenes for the renderer (builtin_scenes.h, scene_poser.h): the default scene's contents and placement,
// ScenePoser's world-space poses (an instance's patches are its model's patches transformed), and
// one-model scenes standing on the ground inside their camera path's view.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_poser.h"

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
        cull_frustum_scalar(batch.view(), nullptr,
                            make_frustum_planes(camera.view_projection(), ClipDepth::zero_to_one), culled.data());
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
        cull_frustum_scalar(batch.view(), nullptr,
                            make_frustum_planes(camera.view_projection(), ClipDepth::zero_to_one), culled.data());
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

// ---- mirrored instances (ScenePoser transposes their patches) ----------------------------------

namespace {

Mat4 diagonal(float x, float y, float z) {
    Mat4 m;
    m.at(0, 0) = x;
    m.at(1, 1) = y;
    m.at(2, 2) = z;
    return m;
}

Vec3 linear_part(const Mat4& m, Vec3 d) { return xyz(m * Vec4{d.x, d.y, d.z, 0}); }

// Signed volume of a set of patches, 1/3 sum of P . (Pu x Pv) over an n x n midpoint grid per patch
// (the divergence theorem; positive for a closed surface whose du x dv points outward).
double patch_volume(const std::vector<BezierPatch>& patches, std::size_t first, std::size_t count, Vec3 centre,
                    int n = 6) {
    double v = 0;
    for (std::size_t p = first; p < first + count; ++p)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const SurfacePoint s = evaluate_surface(patches[p], (i + 0.5f) / n, (j + 0.5f) / n);
                const Vec3 q = s.position - centre;  // about a point near the model: less cancellation
                v += (double(q.x) * s.normal.x + double(q.y) * s.normal.y + double(q.z) * s.normal.z) / (3.0 * n * n);
            }
    return v;
}

}  // namespace

TEST(DefaultScene, InstanceMirrorsIsTheDeterminantsSign) {
    SceneInstance instance;
    EXPECT_FALSE(instance_mirrors(instance));
    instance.object_to_world = diagonal(-1, 1, 1);
    EXPECT_TRUE(instance_mirrors(instance));
    instance.object_to_world = diagonal(-1, -1, 1);  // a half turn: no mirror
    EXPECT_FALSE(instance_mirrors(instance));
    instance.object_to_world = diagonal(-1, -1, -1);
    EXPECT_TRUE(instance_mirrors(instance));
    instance.object_to_world = diagonal(-1, 0, 1);  // singular
    EXPECT_FALSE(instance_mirrors(instance));
    instance.object_to_world = diagonal(1e-3f, 1e-3f, -1e-3f);  // tiny but mirrored
    EXPECT_TRUE(instance_mirrors(instance));
    instance.object_to_world = diagonal(1, 1, -1);
    instance.velocity = {3, 0, 0};
    EXPECT_TRUE(instance_mirrors(instance));
}

// A mirrored BigGuy (deforming, displaced, with ACC tangent patches) next to the unmirrored one:
// its patches are the transposed mirror images (bit for bit), the same surfaces at (v, u), with
// du x dv the mirrored outward normal, ACC normals and texcoords that follow; the posed closed
// surface has positive volume (it is right side out), which the plain mirror image has not. Also
// far from the origin (1e4) and with a mirror that is also rotated and scaled unevenly.
TEST(DefaultScene, MirroredInstancesArePosedRightSideOut) {
    Scene scene = make_model_scene(load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0));
    ASSERT_TRUE(scene.models[0].closed);
    scene.displacement = make_procedural_displacement(64, 0.02f);
    scene.displacement_name = "procedural";
    scene.instances[0].displaced = true;
    scene.instances[0].time_offset = 0.3f;
    const Mat4 standing = scene.instances[0].object_to_world;
    Mat4 tilted;  // a rotation about y by 30 degrees, then a mirror in z with uneven scale
    tilted.at(0, 0) = 0.8660254f, tilted.at(0, 2) = 0.5f, tilted.at(2, 0) = -0.5f, tilted.at(2, 2) = 0.8660254f;
    tilted = diagonal(1.5f, 0.7f, -1.2f) * tilted;
    struct Case {
        const char* name;
        Mat4 linear;
        Vec3 offset;
    };
    const Case cases[] = {{"mirror x", diagonal(-1, 1, 1), {3, 0, 0}},
                          {"mirror x at 1e4", diagonal(-1, 1, 1), {1e4f, 0, -1e4f}},
                          {"tilted mirror", tilted, {-3, 0, 1}},
                          {"unmirrored copy", diagonal(1, 1, 1), {0, 0, 3}}};
    for (const Case& c : cases) {
        SceneInstance copy = scene.instances[0];
        copy.name = std::string("bigguy#") + c.name;
        Mat4 t;
        t.at(0, 3) = c.offset.x, t.at(1, 3) = c.offset.y, t.at(2, 3) = c.offset.z;
        copy.object_to_world = t * c.linear * standing;
        scene.instances.push_back(copy);
    }
    const std::size_t n = scene.models[0].rest.patches.size();
    ScenePoser poser(scene);
    const float time = 0.2f;
    const std::vector<BezierPatch>& posed = poser.pose(time);
    ASSERT_EQ(posed.size(), 5 * n);
    ASSERT_EQ(poser.texcoords().size(), 5 * n);

    // The model's frame at the shared effective time, for the bit-for-bit check.
    std::vector<Vec3> positions;
    PatchFrame frame;
    animate(scene.models[0].subdiv->mesh.positions, time + scene.instances[0].time_offset, scene.animation, positions);
    evaluate_frame(scene.models[0], positions, frame);

    const Bounds b0 = bounds_of(posed, 0, n);
    const double v0 = patch_volume(posed, 0, n, b0.center());
    EXPECT_GT(v0, 0.0);
    for (std::size_t k = 0; k < 4; ++k) {
        const Case& c = cases[k];
        const SceneInstance& instance = scene.instances[k + 1];
        const bool mirrored = k < 3;
        ASSERT_EQ(instance_mirrors(instance), mirrored) << c.name;
        const std::size_t first = (k + 1) * n;
        const Mat4 to_world = instance_to_world(instance, time);
        double det = 0;
        {
            const Mat4& l = c.linear;
            auto a = [&](int r, int cc) { return double(l.at(r, cc)); };
            det = a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) -
                  a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) + a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
        }
        // Outward normals map by the inverse transpose of the linear part.
        Mat4 inverse;
        ASSERT_TRUE(invert(c.linear, inverse));
        auto normal_map = [&](Vec3 nn) {
            return Vec3{inverse.at(0, 0) * nn.x + inverse.at(1, 0) * nn.y + inverse.at(2, 0) * nn.z,
                        inverse.at(0, 1) * nn.x + inverse.at(1, 1) * nn.y + inverse.at(2, 1) * nn.z,
                        inverse.at(0, 2) * nn.x + inverse.at(1, 2) * nn.y + inverse.at(2, 2) * nn.z};
        };
        const float scale = 1.0f + length(c.offset);  // positions' magnitude, for tolerances
        // At 1e4 the float control points are rounded by ~1e-3 of patches ~0.05 across: the
        // normals of both poses turn by a few degrees (their sign is what must agree).
        const float min_cos = scale > 100 ? 0.5f : 0.999f;
        std::size_t normals_checked = 0, acc_checked = 0;
        for (std::size_t p = 0; p < n; ++p) {
            const BezierPatch& a = posed[p];          // the unmirrored instance (object_to_world = standing)
            const BezierPatch& m = posed[first + p];  // this instance
            // Control points: instance_to_world times the model's, transposed when mirrored.
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i) {
                    const Vec4 e = to_world * frame.patches[p].cp[mirrored ? 4 * i + j : 4 * j + i];
                    const Vec4 g = m.cp[4 * j + i];
                    ASSERT_TRUE(g.x == e.x && g.y == e.y && g.z == e.z && g.w == e.w) << c.name << " patch " << p;
                }
            ASSERT_EQ(poser.depth()[first + p], poser.depth()[p]);
            // Texcoords: corners (1,0) and (0,1) swap; the displacement range stays.
            const auto& ta = poser.texcoords()[p];
            const auto& tm = poser.texcoords()[first + p];
            const int swap[4] = {0, 2, 1, 3};
            for (int q = 0; q < 4; ++q) {
                EXPECT_EQ(tm[q].x, ta[mirrored ? swap[q] : q].x);
                EXPECT_EQ(tm[q].y, ta[mirrored ? swap[q] : q].y);
            }
            EXPECT_EQ(poser.displacement_ranges()[first + p].d_min, poser.displacement_ranges()[p].d_min);
            EXPECT_EQ(poser.displacement_ranges()[first + p].d_max, poser.displacement_ranges()[p].d_max);
            // Dense samples: the same surface (the image of the unmirrored one), du x dv the image
            // of the unmirrored outward normal (by the inverse transpose), same direction.
            if (p % 7 == 0) {
                for (int sj = 0; sj <= 8; ++sj)
                    for (int si = 0; si <= 8; ++si) {
                        const float u = si / 8.0f, v = sj / 8.0f;
                        const SurfacePoint sa = evaluate_surface(a, u, v);
                        const SurfacePoint sm = mirrored ? evaluate_surface(m, v, u) : evaluate_surface(m, u, v);
                        const Vec3 expected = linear_part(c.linear, sa.position) + c.offset;
                        ASSERT_LT(length(sm.position - expected), 2e-6f * scale) << c.name << " patch " << p;
                        const Vec3 na = normal_map(sa.normal);
                        if (length(na) < 1e-6f || length(sm.normal) < 1e-9f) continue;
                        ASSERT_GT(dot(normalize(sm.normal), normalize(na)), min_cos)
                            << c.name << " patch " << p << " (" << u << ", " << v << ")";
                        ++normals_checked;
                    }
            }
            // ACC tangent patches: the shading normal at (v, u) is the mirrored one, scaled by |det|.
            const std::int32_t ia = poser.tangent_index()[p], im = poser.tangent_index()[first + p];
            ASSERT_EQ(ia >= 0, im >= 0);
            if (ia < 0) continue;
            const TangentPatches& tp_a = poser.tangents()[static_cast<std::size_t>(ia)];
            const TangentPatches& tp_m = poser.tangents()[static_cast<std::size_t>(im)];
            for (float u : {0.0f, 0.3f, 1.0f})
                for (float v : {0.0f, 0.6f, 1.0f}) {
                    const Vec3 na =
                        normal_map(evaluate_tangent_normal(tp_a, u, v)) * static_cast<float>(std::fabs(det));
                    const Vec3 nm =
                        mirrored ? evaluate_tangent_normal(tp_m, v, u) : evaluate_tangent_normal(tp_m, u, v);
                    ASSERT_LT(length(nm - na), 1e-3f * length(na) + 1e-9f) << c.name << " patch " << p;
                    // ... and the ACC normal agrees in direction with the patch's own du x dv.
                    const SurfacePoint sm = mirrored ? evaluate_surface(m, v, u) : evaluate_surface(m, u, v);
                    if (length(sm.normal) > 1e-6f * length(nm)) {
                        EXPECT_GT(dot(sm.normal, nm), 0.0f) << c.name << " patch " << p;
                    }
                    ++acc_checked;
                }
        }
        EXPECT_GT(normals_checked, n * 81 / 7 / 2) << c.name;
        EXPECT_GT(acc_checked, 100u) << c.name;
        // Right side out: the posed closed surface has positive volume, |det| times the model's
        // (the volume's quadrature rounds the same way for both); the naive mirror image (the
        // model's patches transformed without the transposition) is inside out.
        const Bounds bm = bounds_of(posed, first, n);
        const double vm = patch_volume(posed, first, n, bm.center());
        EXPECT_GT(vm, 0.0) << c.name;
        EXPECT_NEAR(vm, v0 * std::fabs(det), 1e-3 * v0 * std::fabs(det)) << c.name;
        std::vector<BezierPatch> naive(n);
        for (std::size_t p = 0; p < n; ++p)
            for (int q = 0; q < kPatchPoints; ++q) naive[p].cp[q] = to_world * frame.patches[p].cp[q];
        const double vn = patch_volume(naive, 0, n, bm.center());
        if (mirrored) {
            EXPECT_LT(vn, 0.0) << c.name;
        } else {
            EXPECT_GT(vn, 0.0) << c.name;
        }
    }
}
