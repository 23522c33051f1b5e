// ScenePoser::gpu_tables / gpu_meshes (scene_poser.h, GPU posing): the stencil rows
// applied to the posed control meshes and mapped by each instance's transform (rows read
// transposed for mirrored instances) reproduce pose() and tangents() bit for bit, on the CPU (the
// compute pass repeats this arithmetic: tests/gl/gpu_posing_test.cpp checks the GPU's). Groups
// follow pose()'s: one mesh per (model, effective time); rigid instances share the rest mesh.
#include <gtest/gtest.h>

#include <vector>

#include "core/test_patches.h"
#include "patchcull/core/error.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/import/scene_poser.h"

using namespace patchcull;

namespace {

Vec3 linear(const Mat4& m, Vec3 d) {
    const Vec4 r = m * Vec4{d.x, d.y, d.z, 0.0f};
    return {r.x, r.y, r.z};
}

void expect_tables_reproduce_pose(const Scene& scene, float t) {
    ScenePoser reference(scene), poser(scene);
    const std::vector<BezierPatch>& posed = reference.pose(t);
    const std::vector<PoseModelTables>& tables = poser.gpu_tables();
    const PoseMeshes& meshes = poser.gpu_meshes(t);
    ASSERT_EQ(tables.size(), scene.models.size());
    std::size_t next = 0, mismatches = 0;
    std::vector<Vec3> rows;
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const PoseModelTables& table = tables[scene.instances[i].model];
        const Vec3* vertices = meshes.vertices.data() + meshes.first_vertex[i];
        ASSERT_LE(meshes.first_vertex[i] + table.vertex_count, meshes.vertices.size());
        rows.resize(table.patch_points->rows());
        table.patch_points->apply(vertices, rows.data());
        std::vector<Vec3> tangent_rows(table.tangent_points->rows());
        table.tangent_points->apply(vertices, tangent_rows.data());
        const bool mirrored = meshes.mirrored[i] != 0;
        for (std::size_t p = 0; p < table.tangent_index.size(); ++p, ++next) {
            BezierPatch mine;
            for (int k = 0; k < kPatchPoints; ++k) {
                const int source = mirrored ? 4 * (k % 4) + k / 4 : k;
                mine.cp[k] = meshes.to_world[i] * homogeneous(rows[16 * p + static_cast<std::size_t>(source)]);
            }
            mismatches += test_patches::bit_identical(mine, posed[next]) ? 0 : 1;
            const std::int32_t tb = table.tangent_index[p];
            ASSERT_EQ(tb >= 0, reference.tangent_index()[next] >= 0);
            if (tb < 0) continue;
            // The block's rows, mapped (transposed for mirrored instances, as pose()).
            const Vec3* src = tangent_rows.data() + 24 * static_cast<std::size_t>(tb);
            const TangentPatches& expected =
                reference.tangents()[static_cast<std::size_t>(reference.tangent_index()[next])];
            for (int k = 0; k < 12; ++k) {
                Vec3 du, dv;
                if (mirrored) {
                    du = linear(meshes.to_world[i], src[12 + 4 * (k % 3) + k / 3]);
                    dv = linear(meshes.to_world[i], src[3 * (k % 4) + k / 4]);
                } else {
                    du = linear(meshes.to_world[i], src[k]);
                    dv = linear(meshes.to_world[i], src[12 + k]);
                }
                mismatches += test_patches::bit_identical(du, expected.du[k]) ? 0 : 1;
                mismatches += test_patches::bit_identical(dv, expected.dv[k]) ? 0 : 1;
            }
        }
    }
    EXPECT_EQ(next, posed.size());
    EXPECT_EQ(mismatches, 0u) << scene.name << " t=" << t;
}

}  // namespace

TEST(PoseTables, ReproducePoseBitForBitWithMirroredRigidAndWalkingInstances) {
    Scene scene = make_default_scene(Scheme::acc);
    Mat4 mirror;
    mirror.at(0, 0) = -1;
    scene.instances[0].object_to_world = mirror * scene.instances[0].object_to_world;
    scene.instances[1].deforms = false;
    scene.instances[4].velocity = {0.2f, 0, -0.1f};
    for (float t : {0.0f, 0.25f, 1.3f}) expect_tables_reproduce_pose(scene, t);
}

TEST(PoseTables, GroupsShareMeshesAsPoseDoes) {
    Scene scene = make_default_scene(Scheme::acc);
    for (SceneInstance& i : scene.instances) i.time_offset = 0;  // one effective time per model
    // Instances alternate BigGuy (0, 2, 4) and MonsterFrog (1, 3, 5); BigGuy 4 rigid: the rest mesh.
    scene.instances[4].deforms = false;
    ScenePoser poser(scene);
    const PoseMeshes& meshes = poser.gpu_meshes(0.5f);
    const std::size_t bigguy = scene.models[scene.instances[0].model].subdiv->mesh.positions.size();
    const std::size_t frog = scene.models[scene.instances[1].model].subdiv->mesh.positions.size();
    EXPECT_EQ(meshes.vertices.size(), 2 * bigguy + frog);  // animated BigGuy, rest BigGuy, frog
    EXPECT_EQ(meshes.first_vertex[0], meshes.first_vertex[2]);
    EXPECT_NE(meshes.first_vertex[0], meshes.first_vertex[4]);
    EXPECT_EQ(meshes.first_vertex[1], meshes.first_vertex[3]);
    EXPECT_EQ(meshes.first_vertex[1], meshes.first_vertex[5]);
    expect_tables_reproduce_pose(scene, 0.5f);
}

TEST(PoseTables, TeapotGetsIdentityRowsAndSplitsAreRefused) {
    const Scene teapot = make_model_scene(load_model("teapot", Scheme::acc, 0));
    expect_tables_reproduce_pose(teapot, 0.0f);
    const Scene split_scene = make_model_scene(load_model("teapot", Scheme::acc, 1));
    ScenePoser split(split_scene);
    EXPECT_THROW(split.gpu_tables(), Error);
}
