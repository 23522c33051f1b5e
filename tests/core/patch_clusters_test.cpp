// Clusters of patches for clustered back-face culling (patchcull/objects/backface_clusters.h, beyond
// G. Zachmann's lecture; the planes are Loop, Niessner & Eisenacher's tangent control planes,
// "Effective Back-Patch Culling for Hardware Tessellation"): the object-space control planes
// against the sampled tangent planes and a long-double reference, cluster culls against dense
// tangent-plane samples under random rigid motions, and BigGuy's clusters against the per-patch
// back-patch kernels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/error.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/core/teapot.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/objects/backface_clusters.h"

using namespace patchcull;

namespace {

double bern7(int i, double t) {
    static const double binom[8] = {1, 7, 21, 35, 35, 21, 7, 1};
    return binom[i] * std::pow(t, i) * std::pow(1 - t, 7 - i);
}

BezierPatch random_patch(std::mt19937& rng, Vec3 centre, float size, bool rational) {
    std::uniform_real_distribution<float> u(-1, 1), w(0.5f, 2.0f);
    BezierPatch p;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const Vec3 q = centre + Vec3{size * (i / 3.0f - 0.5f) + 0.15f * size * u(rng),
                                         size * (j / 3.0f - 0.5f) + 0.15f * size * u(rng), 0.3f * size * u(rng)};
            p.cp[4 * j + i] = homogeneous(q, rational ? w(rng) : 1.0f);
        }
    return p;
}

// Long-double reference of patch_control_planes (same table, same translation).
struct TableRow {
    int dest, j, k, l;
    long long num, den;
};
constexpr TableRow kTable[] = {
#include "core/ptp_table.inc"
};

void reference_planes(const BezierPatch& patch, Vec3 o, long double out[64][4]) {
    long double L[16][4];
    for (int k = 0; k < 16; ++k) {
        const Vec4 p = patch.cp[k];
        L[k][0] = (long double)p.x - (long double)o.x * p.w;
        L[k][1] = (long double)p.y - (long double)o.y * p.w;
        L[k][2] = (long double)p.z - (long double)o.z * p.w;
        L[k][3] = p.w;
    }
    for (int d = 0; d < 64; ++d)
        for (int c = 0; c < 4; ++c) out[d][c] = 0;
    auto det3 = [](long double a0, long double a1, long double a2, long double b0, long double b1, long double b2,
                   long double c0, long double c1, long double c2) {
        return a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0);
    };
    for (const TableRow& r : kTable) {
        const long double *a = L[r.j], *b = L[r.k], *c = L[r.l];
        const long double w = (long double)r.num / r.den;
        out[r.dest][0] += w * det3(a[1], b[1], c[1], a[2], b[2], c[2], a[3], b[3], c[3]);
        out[r.dest][1] -= w * det3(a[0], b[0], c[0], a[2], b[2], c[2], a[3], b[3], c[3]);
        out[r.dest][2] += w * det3(a[0], b[0], c[0], a[1], b[1], c[1], a[3], b[3], c[3]);
        out[r.dest][3] -= w * det3(a[0], b[0], c[0], a[1], b[1], c[1], a[2], b[2], c[2]);
    }
}

// Rigid motion: rotation (unit quaternion) then translation, in double.
struct Rigid {
    double r[3][3];
    double t[3];
    Vec3 apply(Vec3 p) const {
        double o[3];
        for (int i = 0; i < 3; ++i) o[i] = r[i][0] * p.x + r[i][1] * p.y + r[i][2] * p.z + t[i];
        return {float(o[0]), float(o[1]), float(o[2])};
    }
    Vec3 inverse(Vec3 p) const {  // R^T (p - t)
        const double d[3] = {p.x - t[0], p.y - t[1], p.z - t[2]};
        double o[3];
        for (int i = 0; i < 3; ++i) o[i] = r[0][i] * d[0] + r[1][i] * d[1] + r[2][i] * d[2];
        return {float(o[0]), float(o[1]), float(o[2])};
    }
    BezierPatch apply(const BezierPatch& p) const {
        BezierPatch q;
        for (int k = 0; k < 16; ++k) q.cp[k] = homogeneous(apply(cartesian(p.cp[k])), p.cp[k].w);
        return q;
    }
};

Rigid random_rigid(std::mt19937& rng, double reach) {
    std::normal_distribution<double> n;
    std::uniform_real_distribution<double> u(-1, 1);
    double q[4] = {n(rng), n(rng), n(rng), n(rng)};
    const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (double& v : q) v /= len;
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    Rigid m{{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
             {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
             {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}},
            {reach * u(rng), reach * u(rng), reach * u(rng)}};
    return m;
}

bool patch_faces(const BezierPatch& p, Vec3 eye, int grid) {
    std::vector<PlaneD> planes(grid * grid);
    sample_tangent_planes(p, grid, planes.data());
    return any_plane_faces_eye(planes.data(), planes.size(), eye);
}

}  // namespace

TEST(PatchClusters, ControlPlanesCombineToTheTangentPlanesAndBoundTheirRounding) {
    std::mt19937 rng(51);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int k = 0; k < 40; ++k) {
        const float off = (k % 4) * 2.5e4f;
        const BezierPatch p =
            random_patch(rng, {off + u(rng), off * 0.5f, 2 * u(rng)}, k % 5 == 0 ? 1e-3f : 1.0f, k % 2 == 1);
        // Object space (origin 0): the Bernstein combination is the sampled tangent plane (near the
        // origin only: far away both double computations cancel ~R^3 down to the plane's size).
        PlaneD t[64], err[64];
        patch_control_planes(p, {0, 0, 0}, t, err);
        const int g = off == 0 ? 5 : 0;
        std::vector<PlaneD> s(g * g);
        sample_tangent_planes(p, g, s.data());
        for (int j = 0; j < g; ++j)
            for (int i = 0; i < g; ++i) {
                const double uu = i / double(g - 1), vv = j / double(g - 1);
                double c[4] = {0, 0, 0, 0}, mag = 0;
                for (int jv = 0; jv < 8; ++jv)
                    for (int iu = 0; iu < 8; ++iu) {
                        const double b = bern7(iu, uu) * bern7(jv, vv);
                        const PlaneD& q = t[8 * jv + iu];
                        c[0] += b * q.x, c[1] += b * q.y, c[2] += b * q.z, c[3] += b * q.w;
                        mag += b * (std::fabs(q.x) + std::fabs(q.y) + std::fabs(q.z) + std::fabs(q.w));
                    }
                const PlaneD& r = s[j * g + i];
                const double tol = 1e-9 * (mag + 1e-30);
                EXPECT_NEAR(c[0], r.x, tol);
                EXPECT_NEAR(c[1], r.y, tol);
                EXPECT_NEAR(c[2], r.z, tol);
                EXPECT_NEAR(c[3], r.w, tol * (1 + std::fabs(off)));
            }
        // Local origin: error bounds hold against long double.
        const Vec3 o = cartesian(p.cp[5]);
        patch_control_planes(p, o, t, err);
        long double ref[64][4];
        reference_planes(p, o, ref);
        for (int d = 0; d < 64; ++d) {
            const double v[4] = {t[d].x, t[d].y, t[d].z, t[d].w}, e[4] = {err[d].x, err[d].y, err[d].z, err[d].w};
            for (int c = 0; c < 4; ++c) {
                EXPECT_LE(std::fabs((long double)v[c] - ref[d][c]), (long double)e[c])
                    << "plane " << d << " comp " << c;
                EXPECT_LT(e[c], 1e-9 * (1 + std::fabs(v[c])) + 1e-9);  // and the bound is not vacuous
            }
        }
    }
}

TEST(PatchClusters, CollapsedEdgePlanesAreExactZeros) {
    const auto teapot = teapot_patches();
    PlaneD t[64], err[64];
    patch_control_planes(teapot[20], cartesian(teapot[20].cp[0]), t, err);  // the knob: v = 0 collapses
    for (int iu = 0; iu < 8; ++iu) {
        const PlaneD& q = t[iu];
        EXPECT_EQ(q.x, 0.0);
        EXPECT_EQ(q.y, 0.0);
        EXPECT_EQ(q.z, 0.0);
        EXPECT_EQ(q.w, 0.0);
        EXPECT_EQ(err[iu].x + err[iu].y + err[iu].z + err[iu].w, 0.0);
    }
    // A flat patch in z = 0 with its v = 0 edge collapsed to a point: (u v, v, 0), normal (0, 0, v).
    // Its 8 zero planes are left out of the cluster, so eyes below still cull it (with them, d
    // could not exceed 0 and the normal box would hold 0: nothing culled).
    BezierPatch fan;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) fan.cp[4 * j + i] = {(i / 3.0f) * (j / 3.0f), j / 3.0f, 0, 1};
    patch_control_planes(fan, {0, 0, 0}, t, err);
    int zeros = 0;
    for (int k = 0; k < 64; ++k) zeros += t[k].x == 0 && t[k].y == 0 && t[k].z == 0 && t[k].w == 0;
    EXPECT_EQ(zeros, 8);
    const BackfaceCluster c = make_patch_cluster(&fan, 0, 1);
    EXPECT_TRUE(cluster_backfacing(c, {0.3f, 0.5f, -1}));
    EXPECT_TRUE(cluster_backfacing(c, {30, -50, -0.01f}));
    EXPECT_FALSE(cluster_backfacing(c, {0.3f, 0.5f, 0.01f}));
    EXPECT_NEAR(culling_probability(c, {{-2, -2, -2}, {2, 2, 2}}), 0.5, 1e-6);
}

TEST(PatchClusters, CulledClustersHoldOnlyBackFacingPatchesUnderRigidMotion) {
    std::mt19937 rng(52);
    std::uniform_real_distribution<float> u(-1, 1);
    EXPECT_THROW(build_patch_clusters(nullptr, 0, 1.0, 0), Error);
    EXPECT_TRUE(build_patch_clusters(nullptr, 0, 1.0, 8).nodes.empty());
    // The teapot's 32 patches, split once (128), plus a few rational ones.
    std::vector<BezierPatch> patches;
    for (const BezierPatch& p : teapot_patches()) {
        BezierPatch four[4];
        split_patch(p, four);
        patches.insert(patches.end(), four, four + 4);
    }
    for (int k = 0; k < 8; ++k) patches.push_back(random_patch(rng, {4 + u(rng), u(rng), u(rng)}, 0.5f, true));
    const ClusterHierarchy h = build_patch_clusters(patches.data(), patches.size(), 0.05, 8);
    ASSERT_GT(cluster_leaf_count(h), 1u);
    EXPECT_TRUE(h.indices.empty());
    std::uint32_t next = 0;
    for (std::size_t l = 0; l < cluster_leaf_count(h); ++l) {
        EXPECT_EQ(cluster_leaf(h, l).first, next);
        next += cluster_leaf(h, l).count;
    }
    EXPECT_EQ(next, patches.size());
    std::size_t culled = 0, truth_back = 0, frames = 0;
    for (int m = 0; m < 12; ++m) {
        const Rigid motion = random_rigid(rng, m % 2 ? 3e4 : 5.0);
        std::vector<BezierPatch> world(patches.size());
        for (std::size_t i = 0; i < patches.size(); ++i) world[i] = motion.apply(patches[i]);
        for (int k = 0; k < 15; ++k, ++frames) {
            Vec3 dir{u(rng), u(rng), u(rng)};
            const Vec3 eye_obj_wanted = normalize(dir) * (k % 3 == 0 ? 2.5f : 8.0f);
            const Vec3 eye_world = motion.apply(eye_obj_wanted);
            const Vec3 eye = motion.inverse(eye_world);  // the eye moved into object space
            std::vector<std::uint8_t> leaf(cluster_leaf_count(h), 9);
            std::uint32_t tests = 0;
            cull_cluster_hierarchy(h, eye, leaf.data(), tests);
            for (std::size_t l = 0; l < leaf.size(); ++l) {
                const BackfaceCluster& c = cluster_leaf(h, l);
                EXPECT_EQ(bool(leaf[l]), cluster_backfacing(c, eye)) << "hierarchy differs from the leaf alone";
                for (std::size_t i = c.first; i < c.first + c.count; ++i) {
                    const bool faces_obj = patch_faces(patches[i], eye, 17);
                    if (!faces_obj) ++truth_back;
                    if (!leaf[l]) continue;
                    ++culled;
                    ASSERT_FALSE(faces_obj) << "culled patch " << i << " faces the eye (object space)";
                    ASSERT_FALSE(patch_faces(world[i], eye_world, 17))
                        << "culled patch " << i << " faces the eye (world)";
                }
            }
        }
    }
    EXPECT_GT(culled, truth_back / 5);
    std::printf("[ info ] teapot x4 + rational: clusters cull %.3f of patches, back-facing by samples %.3f\n",
                culled / double(frames * patches.size()), truth_back / double(frames * patches.size()));
}

TEST(PatchClusters, BigGuyClustersAgainstThePerPatchKernels) {
    const LoadedModel model = load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0);
    ASSERT_TRUE(model.closed);
    const std::vector<BezierPatch>& patches = model.rest.patches;
    const PatchBatch batch = make_batch(patches);
    for (double tcr : {0.01, 0.1, 1.0}) {
        const ClusterHierarchy h = build_patch_clusters(patches.data(), patches.size(), tcr, 16);
        const Bounds box = patch_bounds(model.rest);
        const Vec3 centre = box.center();
        const float radius = box.radius();
        std::mt19937 rng(53);
        std::uniform_real_distribution<float> u(-1, 1);
        std::size_t by_cluster = 0, by_ptp = 0, by_tcone = 0, cluster_not_ptp = 0, tests_total = 0, frames = 0;
        for (int k = 0; k < 24; ++k, ++frames) {
            const Vec3 eye = centre + normalize(Vec3{u(rng), u(rng), u(rng)}) * (radius * (k % 2 ? 2.0f : 4.0f));
            const Mat4 proj = perspective(0.9f, 1.0f, 0.1f * radius, 20 * radius);
            const Mat4 m = proj * look_at(eye, centre, {0, 1, 0});
            std::vector<std::uint8_t> ptp(patches.size()), tcone(patches.size()), leaf(cluster_leaf_count(h));
            cull_ptp_scalar(batch.view(), m, clip_space_eye_alpha(proj), PtpRule::pcnt, ptp.data());
            cull_tcone_scalar(batch.view(), eye, tcone.data());
            std::uint32_t tests = 0;
            cull_cluster_hierarchy(h, eye, leaf.data(), tests);
            tests_total += tests;
            for (std::size_t l = 0; l < leaf.size(); ++l) {
                if (!leaf[l]) continue;
                const BackfaceCluster& c = cluster_leaf(h, l);
                for (std::size_t i = c.first; i < c.first + c.count; ++i) {
                    ++by_cluster;
                    cluster_not_ptp += !ptp[i];
                    ASSERT_FALSE(patch_faces(patches[i], eye, 9))
                        << "BigGuy patch " << i << " culled but faces the eye";
                }
            }
            for (std::size_t i = 0; i < patches.size(); ++i) by_ptp += ptp[i], by_tcone += tcone[i];
        }
        const double n = double(frames * patches.size());
        std::printf(
            "[ info ] BigGuy (%zu patches, tC/r %g: %zu leaves, %zu nodes): culled by clusters %.3f, by ptp-pcnt %.3f, "
            "by tcone %.3f; cluster tests/frame %.1f vs %zu per-patch tests; cluster-culled not culled by ptp: %zu\n",
            patches.size(), tcr, cluster_leaf_count(h), h.nodes.size(), by_cluster / n, by_ptp / n, by_tcone / n,
            tests_total / double(frames), patches.size(), cluster_not_ptp);
        EXPECT_GT(by_cluster, 0u);
        EXPECT_LE(by_cluster, by_ptp + cluster_not_ptp);
        // Every patch of a culled cluster has all 64 control planes behind the eye: ptp-pcnt (the same
        // planes in clip space, with its own rounding margin) culls it too, but for rounding.
        EXPECT_LE(cluster_not_ptp, by_cluster / 100 + 1);
    }
}
