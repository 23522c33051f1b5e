// PatchTruthWindow (ground_truth.h), the streamed ground truth, against the eager
// functions it replaces in `cull`: the same answer for every patch, view and slot, across window
// moves (clear), displaced or not, near and far from the origin, for degenerate patches, and with
// the samples of a slot made once per window however many views ask.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/core/error.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/core/mesh.h"
#include "patchcull/core/teapot.h"

using namespace patchcull;

namespace {

struct TruthCase {
    BezierPatch patch;
    TangentPatches tangents;
    bool has_tangents = false;
    Vec2 uv[4];
    PatchTruthInput input() const { return {&patch, has_tangents ? &tangents : nullptr, uv}; }
};

// Teapot patches, jittered, scaled and moved, with random texture windows and, for every other
// patch, random tangent patches (they only tilt the displacement normal); then a collapsed patch
// (every control point equal) and one with a NaN coordinate.
std::vector<TruthCase> random_cases(std::mt19937& rng, Vec3 offset, float scale) {
    std::uniform_real_distribution<float> jitter(-0.2f, 0.2f), unit(0.0f, 1.0f);
    std::vector<TruthCase> cases;
    for (const BezierPatch& p : teapot_patches()) {
        TruthCase c;
        for (int k = 0; k < kPatchPoints; ++k) {
            const Vec4 q = p.cp[k];
            c.patch.cp[k] = {offset.x + scale * (q.x + jitter(rng)), offset.y + scale * (q.y + jitter(rng)),
                             offset.z + scale * (q.z + jitter(rng)), 1.0f};
        }
        c.has_tangents = cases.size() % 2 == 1;
        for (int k = 0; k < 12; ++k) {
            c.tangents.du[k] = {jitter(rng), jitter(rng), 1.0f + jitter(rng)};
            c.tangents.dv[k] = {1.0f + jitter(rng), jitter(rng), jitter(rng)};
        }
        const Vec2 origin{unit(rng), unit(rng)};
        const float size = 0.05f + 0.3f * unit(rng);
        c.uv[0] = origin;
        c.uv[1] = {origin.x + size, origin.y};
        c.uv[2] = {origin.x, origin.y + size};
        c.uv[3] = {origin.x + size, origin.y + size};
        cases.push_back(c);
    }
    TruthCase collapsed = cases.front();
    for (Vec4& q : collapsed.patch.cp) q = {offset.x, offset.y, offset.z, 1.0f};
    cases.push_back(collapsed);
    TruthCase nan = cases.front();
    nan.patch.cp[5].y = std::numeric_limits<float>::quiet_NaN();
    cases.push_back(nan);
    return cases;
}

Bounds bounds_of(const std::vector<TruthCase>& cases) {
    std::vector<Vec3> points;
    for (const TruthCase& c : cases)
        for (const Vec4& q : c.patch.cp)
            if (is_finite(xyz(q))) points.push_back(xyz(q));
    return compute_bounds(points);
}

// The eager truth, without the sphere shortcut: the window's shortcut must be exact.
bool eager_in_clip(const TruthCase& c, const DisplacementMap* d, int grid, const Mat4& m) {
    std::vector<Vec3> points(static_cast<std::size_t>(grid * grid));
    sample_displaced_patch(c.patch, c.has_tangents ? &c.tangents : nullptr, c.uv, d, grid, points.data());
    return any_point_in_clip_volume(m, points.data(), points.size());
}

bool eager_faces(const TruthCase& c, int grid, Vec3 eye) {
    std::vector<PlaneD> planes(static_cast<std::size_t>(grid * grid));
    sample_tangent_planes(c.patch, grid, planes.data());
    return any_plane_faces_eye(planes.data(), planes.size(), eye);
}

struct Outcomes {
    int visible = 0, hidden = 0, facing = 0, away = 0;
};

// Moves a window of `capacity` slots over the cases (the last window partly filled); in each
// window every view asks about every slot, both kinds. Every answer must equal the eager one, and
// each slot is sampled once per kind per window.
Outcomes compare_over_views(const std::vector<TruthCase>& cases, const DisplacementMap* d, int grid,
                            std::size_t capacity, ViewMode mode, std::uint64_t seed, int views) {
    PatchTruthWindow window(capacity, grid, d, true, true);
    ViewGenerator generator(bounds_of(cases), mode, seed);
    std::vector<Camera> cameras;
    cameras.reserve(views);
    for (int v = 0; v < views; ++v) cameras.push_back(generator.next());
    Outcomes o;
    std::uint64_t expected_samplings = 0;
    for (std::size_t first = 0; first < cases.size(); first += capacity) {
        window.clear();
        const std::size_t count = std::min(capacity, cases.size() - first);
        for (const Camera& camera : cameras) {
            const Mat4 m = camera.view_projection();
            for (std::size_t slot = 0; slot < count; ++slot) {
                const TruthCase& c = cases[first + slot];
                const bool in_clip = window.in_clip_volume(slot, c.input(), m);
                EXPECT_EQ(in_clip, eager_in_clip(c, d, grid, m)) << "patch " << first + slot << " grid " << grid;
                const bool faces = window.faces_eye(slot, c.input(), camera.eye);
                EXPECT_EQ(faces, eager_faces(c, grid, camera.eye)) << "patch " << first + slot << " grid " << grid;
                ++(in_clip ? o.visible : o.hidden);
                ++(faces ? o.facing : o.away);
            }
        }
        expected_samplings += 2 * count;
        EXPECT_EQ(window.samplings(), expected_samplings) << "samples made again within one window";
    }
    return o;
}

}  // namespace

TEST(GroundTruthWindow, EqualsTheEagerTruthNearTheOrigin) {
    std::mt19937 rng(1);
    const std::vector<TruthCase> cases = random_cases(rng, {0, 0, 0}, 1.0f);
    const Outcomes free = compare_over_views(cases, nullptr, 17, 7, ViewMode::free, 3, 24);
    const Outcomes contain = compare_over_views(cases, nullptr, 5, 64, ViewMode::contain, 4, 8);
    // Not vacuous: both answers occur, so a window answering for the wrong patch or a stale one
    // would disagree somewhere.
    EXPECT_GT(free.visible, 50);
    EXPECT_GT(free.hidden, 50);
    EXPECT_GT(free.facing, 50);
    EXPECT_GT(free.away, 50);
    EXPECT_GT(contain.visible, 50);
}

TEST(GroundTruthWindow, EqualsTheEagerTruthDisplacedAndFarFromTheOrigin) {
    std::mt19937 rng(2);
    const std::vector<TruthCase> far = random_cases(rng, {1e4f, -2e4f, 5e3f}, 3.0f);
    const DisplacementMap strong = make_procedural_displacement(64, 0.5f);
    const Outcomes o = compare_over_views(far, &strong, 17, 5, ViewMode::free, 5, 16);
    EXPECT_GT(o.visible, 20);
    EXPECT_GT(o.hidden, 20);
    const std::vector<TruthCase> near = random_cases(rng, {0, 0, 0}, 1.0f);
    const DisplacementMap empty;  // empty: undisplaced samples
    compare_over_views(near, &empty, 3, 33, ViewMode::free, 6, 8);
    compare_over_views(near, &strong, 1, 1, ViewMode::free, 7, 8);  // one sample, one slot
}

TEST(GroundTruthWindow, ClearForgetsASlotsSamples) {
    std::mt19937 rng(3);
    std::vector<TruthCase> cases = random_cases(rng, {0, 0, 0}, 1.0f);
    TruthCase far = cases.front();
    for (Vec4& q : far.patch.cp) q = {q.x + 1000.0f, q.y, q.z, 1.0f};
    Camera camera;  // looks down -z from (0,0,10) at the origin's teapot
    camera.eye = {0, 0, 10};
    camera.target = {0, 0, 0};
    camera.up = {0, 1, 0};
    camera.z_far = 100;
    const Mat4 m = camera.view_projection();
    ASSERT_TRUE(eager_in_clip(cases.front(), nullptr, 17, m));
    ASSERT_FALSE(eager_in_clip(far, nullptr, 17, m));
    PatchTruthWindow window(2, 17, nullptr, true, false);
    EXPECT_TRUE(window.in_clip_volume(1, cases.front().input(), m));
    // Without clear the slot keeps the samples it made (the contract: one patch per slot until
    // clear); after it, the new patch is sampled.
    EXPECT_TRUE(window.in_clip_volume(1, far.input(), m));
    window.clear();
    EXPECT_FALSE(window.in_clip_volume(1, far.input(), m));
    EXPECT_EQ(window.samplings(), 2u);
}

TEST(GroundTruthWindow, BadArgumentsThrow) {
    std::mt19937 rng(4);
    const TruthCase c = random_cases(rng, {0, 0, 0}, 1.0f).front();
    EXPECT_THROW(PatchTruthWindow(0, 17, nullptr, true, true), Error);
    EXPECT_THROW(PatchTruthWindow(4, 0, nullptr, true, true), Error);
    EXPECT_THROW(PatchTruthWindow(4, 1025, nullptr, true, true), Error);
    PatchTruthWindow clip_only(4, 17, nullptr, true, false);
    EXPECT_THROW(clip_only.in_clip_volume(4, c.input(), Mat4{}), Error);
    EXPECT_THROW(clip_only.faces_eye(0, c.input(), {0, 0, 1}), Error);
    PatchTruthWindow facing_only(4, 17, nullptr, false, true);
    EXPECT_THROW(facing_only.in_clip_volume(0, c.input(), Mat4{}), Error);
    EXPECT_THROW(facing_only.faces_eye(7, c.input(), {0, 0, 1}), Error);
    EXPECT_NO_THROW(facing_only.faces_eye(3, c.input(), {0, 0, 1}));
}
