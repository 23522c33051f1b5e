// Watertight tessellation of adaptive (osd) patches (gl_renderer.h, PatchAttributes::depth):
// OpenSubdiv's feature-adaptive refinement puts patches of different depth side by side, and a
// uniform level per patch left T-junctions there, cracks that showed the background through a
// closed surface. With the depth scale, a patch of depth d gets 2^(D-d) times the level, so a
// coarse edge has exactly the vertices of the two finer edges along it. The test counts pinholes
// (background pixels whose four neighbours are all patches) of one-sided BigGuy renders: 248 and
// 96 at levels 1 and 2 over four views before, 6 after (float slivers between patches evaluated
// from different control points, which the scale cannot remove).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/camera.h"
#include "patchcull/gl/gl_renderer.h"
#include "patchcull/import/model_loader.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

constexpr int kSize = 384;

std::size_t pinholes(const std::vector<std::uint32_t>& ids) {
    auto patch = [&](int x, int y) {
        const std::uint32_t id = ids[static_cast<std::size_t>(y) * kSize + x];
        return id != 0 && !(id & kIdOccluderBit);
    };
    std::size_t holes = 0;
    for (int y = 1; y + 1 < kSize; ++y)
        for (int x = 1; x + 1 < kSize; ++x)
            if (ids[static_cast<std::size_t>(y) * kSize + x] == 0 && patch(x - 1, y) && patch(x + 1, y) &&
                patch(x, y - 1) && patch(x, y + 1))
                ++holes;
    return holes;
}

// Pinholes summed over a few views around the model, at tessellation level `level`.
std::size_t pinholes_over_views(PatchRenderer& r, const LoadedModel& model, int level) {
    std::size_t holes = 0;
    for (const Camera& camera : orbit_sequence(patch_bounds(model.rest), 4, 90.0f)) {
        RenderParams rp;
        rp.view = camera.view();
        rp.projection = camera.projection();
        rp.width = rp.height = kSize;
        rp.tess_level = level;
        rp.use_cull_flags = false;
        rp.discard_back_facing = true;
        r.render(rp);
        holes += pinholes(r.read_ids());
    }
    return holes;
}

}  // namespace

TEST(Watertight, OsdPatchesOfDifferentDepthMeetWithoutCracks) {
    const LoadedModel model = load_model(shipped_model_path("bigguy.obj"), Scheme::osd, 0);
    PatchAttributes with_depth;
    int deepest = 0;
    for (const PatchInfo& info : model.rest.info) {
        with_depth.depth.push_back(info.depth);
        deepest = std::max(deepest, int(info.depth));
    }
    ASSERT_GE(deepest, 1);  // adaptive refinement happened: mixed depths

    PatchRenderer r(test::context());
    for (int level : {1, 2}) {
        r.set_patches(model.rest.patches);  // every patch at the same level: T-junctions
        const std::size_t before = pinholes_over_views(r, model, level);
        r.set_patches(model.rest.patches, with_depth);
        const std::size_t after = pinholes_over_views(r, model, level);
        RecordProperty("pinholes_level_" + std::to_string(level),
                       std::to_string(before) + " -> " + std::to_string(after));
        std::printf("pinholes at level %d over 4 views: %zu without the depth scale, %zu with it\n", level, before,
                    after);
        EXPECT_GT(before, 50u) << level;  // the defect is there without the scale (248 and 96 measured)
        // What remains (6 pixels at both levels, measured) lies where two patches, of equal depth
        // too, evaluate their shared boundary from different control points: float rounding
        // opens a sliver a pixel centre can fall into. Not a T-junction.
        EXPECT_LE(after, before / 10) << level;
        EXPECT_LE(after, 12u) << level;
    }
}

TEST(Watertight, DepthAttributeIsChecked) {
    PatchRenderer r(test::context());
    PatchAttributes wrong;
    wrong.depth = {0, 1};
    EXPECT_THROW(r.set_patches(test::split_teapot(0), wrong), patchcull::Error);
}
