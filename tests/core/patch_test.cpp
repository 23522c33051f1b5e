// Bezier patch evaluation, derivatives, exact 1-to-4 split and SoA batches.
#include <gtest/gtest.h>

#include <random>

#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

BezierPatch random_patch(std::mt19937& rng, bool rational) {
    std::uniform_real_distribution<float> coord(-2, 2), weight(0.3f, 3.0f);
    BezierPatch p;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const Vec3 c{i + 0.3f * coord(rng), j + 0.3f * coord(rng), 0.5f * coord(rng)};
            p.cp[4 * j + i] = homogeneous(c, rational ? weight(rng) : 1.0f);
        }
    return p;
}

void expect_near(Vec3 a, Vec3 b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

}  // namespace

TEST(Patch, CornersInterpolateCornerControlPoints) {
    std::mt19937 rng(1);
    const BezierPatch p = random_patch(rng, true);
    expect_near(evaluate_position(p, 0, 0), cartesian(p.cp[0]), 1e-6f);
    expect_near(evaluate_position(p, 1, 0), cartesian(p.cp[3]), 1e-6f);
    expect_near(evaluate_position(p, 0, 1), cartesian(p.cp[12]), 1e-6f);
    expect_near(evaluate_position(p, 1, 1), cartesian(p.cp[15]), 1e-6f);
}

TEST(Patch, DerivativesMatchFiniteDifferencesForRationalPatches) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> param(0.05f, 0.95f);
    for (int trial = 0; trial < 50; ++trial) {
        const BezierPatch p = random_patch(rng, trial % 2 == 1);
        const float u = param(rng), v = param(rng), h = 1e-3f;
        const SurfacePoint s = evaluate_surface(p, u, v);
        const Vec3 du = (evaluate_position(p, u + h, v) - evaluate_position(p, u - h, v)) * (0.5f / h);
        const Vec3 dv = (evaluate_position(p, u, v + h) - evaluate_position(p, u, v - h)) * (0.5f / h);
        expect_near(s.du, du, 2e-2f);
        expect_near(s.dv, dv, 2e-2f);
        expect_near(s.normal, cross(s.du, s.dv), 1e-4f);
    }
}

TEST(Patch, SplitChildrenReproduceTheParentExactly) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> param(0, 1);
    for (int trial = 0; trial < 40; ++trial) {
        const BezierPatch p = random_patch(rng, trial % 2 == 0);
        BezierPatch children[4];
        split_patch(p, children);
        for (int c = 0; c < 4; ++c)
            for (int k = 0; k < 20; ++k) {
                const float u = param(rng), v = param(rng);
                const float pu = 0.5f * u + ((c & 1) ? 0.5f : 0.0f), pv = 0.5f * v + ((c & 2) ? 0.5f : 0.0f);
                expect_near(evaluate_position(children[c], u, v), evaluate_position(p, pu, pv), 2e-5f);
            }
    }
}

TEST(Patch, SplitTangentPatchesFollowTheParent) {
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> coord(-1, 1), param(0, 1);
    TangentPatches t;
    for (Vec3& d : t.du) d = {coord(rng), coord(rng), coord(rng)};
    for (Vec3& d : t.dv) d = {coord(rng), coord(rng), coord(rng)};
    TangentPatches children[4];
    split_tangents(t, children);
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 20; ++k) {
            const float u = param(rng), v = param(rng);
            const float pu = 0.5f * u + ((c & 1) ? 0.5f : 0.0f), pv = 0.5f * v + ((c & 2) ? 0.5f : 0.0f);
            // Each child derivative is half the parent's, so the normal is a quarter.
            expect_near(evaluate_tangent_normal(children[c], u, v) * 4.0f, evaluate_tangent_normal(t, pu, pv), 1e-4f);
        }
}

TEST(Patch, BatchRoundTripsAndPadsWithZeros) {
    std::mt19937 rng(5);
    std::vector<BezierPatch> patches;
    patches.reserve(21);
    for (int i = 0; i < 21; ++i) patches.push_back(random_patch(rng, true));
    const PatchBatch batch = make_batch(patches);
    EXPECT_EQ(batch.size(), 21u);
    EXPECT_EQ(batch.stride() % kBatchAlignment, 0u);
    EXPECT_GE(batch.stride(), 21u);
    for (int i = 0; i < 21; ++i)
        for (int k = 0; k < kPatchPoints; ++k) {
            EXPECT_EQ(batch.get(i).cp[k].x, patches[i].cp[k].x);
            EXPECT_EQ(batch.get(i).cp[k].w, patches[i].cp[k].w);
        }
    for (std::size_t i = 21; i < batch.stride(); ++i) EXPECT_EQ(batch.component(15, 3)[i], 0.0f);
    const PatchBatchView sub = batch.view().subrange(5, 3);
    EXPECT_EQ(sub.component(2, 1)[0], patches[5].cp[2].y);
}
