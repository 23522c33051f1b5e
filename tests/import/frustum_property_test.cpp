// Property tests of the frustum kernels against the dense-sample ground truth:
// thousands of random cameras, including cameras inside the model and near planes that cut
// patches, on real models, displaced and animated. A false cull fails the test; the last test
// shows the ground truth does catch a kernel that is not conservative.
#include <gtest/gtest.h>

#include "patchcull/core/frustum.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/eval/cull_eval.h"
#include "patchcull/import/animation.h"
#include "patchcull/import/model_loader.h"

using namespace patchcull;

namespace {

void expect_conservative(const PatchFrame& frame, const DisplacementMap* disp, ViewMode mode, int views,
                         std::uint64_t seed, double min_cull_rate) {
    CullEvalOptions options;
    options.views = views;
    options.seed = seed;
    options.mode = mode;
    const CullEvalResult r = evaluate_cull(frame, disp, options);
    ASSERT_EQ(r.methods.size(), 2u);
    for (const CullMethodResult& m : r.methods) {
        EXPECT_EQ(m.false_culls, 0u) << m.name << " " << view_mode_name(mode);
        // Not vacuous: free views do cull (a kernel that never culls would pass the line above).
        EXPECT_GE(m.cull_rate, min_cull_rate) << m.name << " " << view_mode_name(mode);
    }
}

DisplacementMap strong_displacement(const PatchFrame& frame) {
    const Bounds b = patch_bounds(frame);
    return make_procedural_displacement(256, 0.08f * length(b.max - b.min));
}

}  // namespace

TEST(FrustumProperty, BigGuyAccFreeAndContainViews) {
    const LoadedModel m = load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0);
    expect_conservative(m.rest, nullptr, ViewMode::free, 1500, 11, 0.2);
    expect_conservative(m.rest, nullptr, ViewMode::contain, 300, 12, 0.0);
}

TEST(FrustumProperty, MonsterFrogAccDisplaced) {
    const LoadedModel m = load_model(shipped_model_path("monsterfrog.obj"), Scheme::acc, 0);
    const DisplacementMap d = strong_displacement(m.rest);
    expect_conservative(m.rest, &d, ViewMode::free, 1500, 21, 0.2);
}

TEST(FrustumProperty, BigGuyOsdDisplaced) {
    const LoadedModel m = load_model(shipped_model_path("bigguy.obj"), Scheme::osd, 0);
    const DisplacementMap d = strong_displacement(m.rest);
    expect_conservative(m.rest, &d, ViewMode::free, 1500, 31, 0.2);
}

TEST(FrustumProperty, TeapotWithDegeneratePatchesSplitTwice) {
    const LoadedModel m = load_model("teapot", Scheme::acc, 2);
    const DisplacementMap d = strong_displacement(m.rest);
    expect_conservative(m.rest, nullptr, ViewMode::free, 2000, 41, 0.2);
    expect_conservative(m.rest, &d, ViewMode::free, 2000, 42, 0.2);
}

TEST(FrustumProperty, AnimatedBigGuy) {
    const LoadedModel m = load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0);
    const DisplacementMap d = strong_displacement(m.rest);
    std::vector<Vec3> positions;
    PatchFrame frame;
    for (int f = 1; f <= 3; ++f) {
        animate(m.subdiv->mesh.positions, 0.37f * f, AnimationParams{}, positions);
        evaluate_frame(m, positions, frame);
        expect_conservative(frame, &d, ViewMode::free, 300, 50 + f, 0.2);
    }
}

// The ground truth must be able to fail: dropping the displacement margin from the frustum
// kernel (a plausible bug) makes it cull displaced patches that are visible, and the same
// ground truth the tests above use reports them.
TEST(FrustumProperty, GroundTruthCatchesAKernelThatIgnoresDisplacement) {
    const LoadedModel m = load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0);
    const DisplacementMap d = strong_displacement(m.rest);
    const PatchBatch batch = make_batch(m.rest.patches);
    const std::size_t n = m.rest.patches.size();
    std::vector<Vec3> samples(n * 289);
    for (std::size_t p = 0; p < n; ++p) {
        const PatchInfo& info = m.rest.info[p];
        const TangentPatches* t = info.tangent_index >= 0 ? &m.rest.tangents[info.tangent_index] : nullptr;
        sample_displaced_patch(m.rest.patches[p], t, info.uv, &d, 17, &samples[p * 289]);
    }
    ViewGenerator views(patch_bounds(m.rest), ViewMode::free, 99);
    std::vector<std::uint8_t> culled(n);
    std::uint64_t false_culls = 0;
    for (int v = 0; v < 200; ++v) {
        const Mat4 clip = views.next().view_projection();
        cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(clip, ClipDepth::zero_to_one),
                            culled.data());  // margin dropped
        for (std::size_t p = 0; p < n; ++p)
            if (culled[p] && any_point_in_clip_volume(clip, &samples[p * 289], 289)) ++false_culls;
    }
    EXPECT_GT(false_culls, 0u);
}
