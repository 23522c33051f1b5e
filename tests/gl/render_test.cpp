// PatchRenderer: the teapot renders into the id/depth/colour buffers with the conventions of
// gl_renderer.h; a flagged patch vanishes and nothing else changes; ids past 256 patches are right
// (llvmpipe's gl_PrimitiveID workaround); high tessellation levels stay correct (sub-draw split).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/camera.h"
#include "patchcull/gl/gl_verification.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

RenderParams front_view(const std::vector<BezierPatch>& patches, int size = 256, int level = 8) {
    const Bounds b = test::control_point_bounds(patches);
    Camera cam;
    cam.target = b.center();
    cam.eye = b.center() + Vec3{0.3f, -1.0f, 0.5f} * (1.8f * b.radius());
    cam.up = {0, 0, 1};
    cam.z_near = 0.1f * b.radius();
    cam.z_far = 10.0f * b.radius();
    RenderParams p;
    p.view = cam.view();
    p.projection = cam.projection();
    p.width = p.height = size;
    p.tess_level = level;
    return p;
}

}  // namespace

TEST(PatchRenderer, TeapotFillsIdDepthAndColourBuffers) {
    const std::vector<BezierPatch> patches = teapot_patches();
    PatchRenderer r(test::context());
    r.set_patches(patches);
    r.render(front_view(patches));
    const auto ids = r.read_ids();
    const auto depth = r.read_depth();
    const auto color = r.read_color();
    ASSERT_EQ(ids.size(), 256u * 256u);
    ASSERT_EQ(depth.size(), ids.size());
    ASSERT_EQ(color.size(), 4 * ids.size());
    std::size_t covered = 0;
    for (std::size_t i = 0; i < ids.size(); ++i) {
        ASSERT_LE(ids[i], patches.size()) << "pixel " << i;
        ASSERT_GE(depth[i], 0.0f);
        ASSERT_LE(depth[i], 1.0f);
        if (ids[i] != 0) {
            ++covered;
            EXPECT_LT(depth[i], 1.0f);
        } else {
            EXPECT_EQ(depth[i], 1.0f);
        }
    }
    // The teapot covers a good part of the view, with many patches (body, spout, handle, lid).
    EXPECT_GT(covered, ids.size() / 10);
    EXPECT_LT(covered, ids.size());
    EXPECT_GE(test::ids_present(ids).size(), 16u);
    // Image order: row 0 is the top. The teapot's z is up, the camera's up is +z, so the lid's knob
    // (patches 20-23, ids 21-24) appears above the bottom edge's rows: its mean row is in the upper half.
    double knob_rows = 0;
    std::size_t knob_pixels = 0;
    for (std::size_t i = 0; i < ids.size(); ++i)
        if (ids[i] >= 21 && ids[i] <= 24) {
            const std::size_t row = i / 256;  // the image is 256 wide
            knob_rows += static_cast<double>(row);
            ++knob_pixels;
        }
    ASSERT_GT(knob_pixels, 0u);
    EXPECT_LT(knob_rows / knob_pixels, 128.0);
    // Colour: background where the id is 0, shaded patch colour elsewhere.
    for (std::size_t i = 0; i < ids.size(); ++i) {
        const bool bg = color[4 * i] == color[4 * 0] && color[4 * i + 1] == color[1] && color[4 * i + 2] == color[2];
        if (ids[i] == 0) {
            EXPECT_TRUE(bg) << "pixel " << i;
        }
        EXPECT_EQ(color[4 * i + 3], 255);
    }
    ASSERT_EQ(ids[0], 0u);  // corner pixel is background (the teapot is centred)
    const std::string dir = ::testing::TempDir();
    r.write_color_png(dir + "/patchcull_teapot.png");
    write_ids_png(dir + "/patchcull_teapot_ids.png", ids, 256, 256);
    EXPECT_GT(std::filesystem::file_size(dir + "/patchcull_teapot.png"), 1000u);
}

TEST(PatchRenderer, FlaggedPatchVanishesAndNothingElseChanges) {
    const std::vector<BezierPatch> patches = teapot_patches();
    PatchRenderer r(test::context());
    r.set_patches(patches);
    const RenderParams params = front_view(patches);
    r.render(params);
    const auto before = r.read_ids();
    const auto depth_before = r.read_depth();
    // The body patch with the most pixels.
    std::vector<std::size_t> pixels(patches.size() + 1, 0);
    for (auto id : before) ++pixels[id];
    const std::uint32_t victim =
        static_cast<std::uint32_t>(std::max_element(pixels.begin() + 1, pixels.end()) - pixels.begin());
    ASSERT_GT(pixels[victim], 100u);

    std::vector<std::uint8_t> culled(patches.size(), 0);
    culled[victim - 1] = 1;
    r.set_cull_flags(culled.data());
    EXPECT_EQ(r.read_cull_flags()[victim - 1], 1u);
    r.render(params);
    const auto after = r.read_ids();
    const auto depth_after = r.read_depth();
    std::size_t changed = 0;
    for (std::size_t i = 0; i < before.size(); ++i) {
        ASSERT_NE(after[i], victim) << "culled patch still drawn at pixel " << i;
        if (before[i] != victim) {
            ASSERT_EQ(after[i], before[i]) << "pixel " << i << " not covered by the culled patch changed";
            ASSERT_EQ(depth_after[i], depth_before[i]) << "pixel " << i;
        } else {
            ++changed;
            EXPECT_GE(depth_after[i], depth_before[i]);  // what shows through lies behind
        }
    }
    EXPECT_EQ(changed, pixels[victim]);

    // use_cull_flags = false draws it again; clear_cull_flags too.
    RenderParams all = params;
    all.use_cull_flags = false;
    r.render(all);
    EXPECT_EQ(r.read_ids(), before);
    r.clear_cull_flags();
    r.render(params);
    EXPECT_EQ(r.read_ids(), before);
}

TEST(PatchRenderer, IdsPastTheFirst256PatchesAreCorrect) {
    // 512 patches = 8192 vertices: llvmpipe's gl_PrimitiveID restarts at 4096 vertices. Draw only
    // patches 300..339: every id in the buffer must be one of them, and several must appear.
    const std::vector<BezierPatch> patches = test::split_teapot(2);
    ASSERT_EQ(patches.size(), 512u);
    PatchRenderer r(test::context());
    r.set_patches(make_batch(patches).view());  // the structure-of-arrays upload path
    std::vector<std::uint8_t> culled(patches.size(), 1);
    for (std::size_t p = 300; p < 340; ++p) culled[p] = 0;
    r.set_cull_flags(culled.data());
    r.render(front_view(patches));
    const auto present = test::ids_present(r.read_ids());
    ASSERT_FALSE(present.empty());
    for (auto id : present) {
        EXPECT_GE(id, 301u);
        EXPECT_LE(id, 340u);
    }
    EXPECT_GE(present.size(), 5u);
    // With every patch drawn, ids above 256 appear.
    r.clear_cull_flags();
    r.render(front_view(patches));
    const auto all = test::ids_present(r.read_ids());
    EXPECT_GT(*all.rbegin(), 256u);
    EXPECT_LE(*all.rbegin(), 512u);
}

TEST(PatchRenderer, HighTessellationLevelMatchesPerPatchDraws) {
    // Level 20 on 512 patches: 441 vertices per patch, 256 patches per 4096-vertex chunk would be
    // 112,896 vertices, past llvmpipe's 65,536 (beyond it llvmpipe emits garbage triangles); the renderer splits draws.
    // Check that drawing all patches equals the depth-merged union of 8 draws of 64 patches each (the others culled: 64
    // * 441 = 28,224 tessellated vertices per chunk, safe even without the split), and that ids stay in range.
    const std::vector<BezierPatch> patches = test::split_teapot(2);
    PatchRenderer r(test::context());
    r.set_patches(patches);
    const RenderParams params = front_view(patches, 128, 20);
    r.render(params);
    const auto ids = r.read_ids();
    const auto depth = r.read_depth();
    std::vector<std::uint32_t> merged(ids.size(), 0);
    std::vector<float> merged_depth(ids.size(), 1.0f);
    for (std::size_t group = 0; group < 8; ++group) {
        std::vector<std::uint8_t> culled(patches.size(), 1);
        for (std::size_t p = group * 64; p < group * 64 + 64; ++p) culled[p] = 0;
        r.set_cull_flags(culled.data());
        r.render(params);
        const auto h_ids = r.read_ids();
        const auto h_depth = r.read_depth();
        for (std::size_t i = 0; i < ids.size(); ++i)
            if (h_depth[i] < merged_depth[i]) {
                merged_depth[i] = h_depth[i];
                merged[i] = h_ids[i];
            }
    }
    std::size_t mismatched = 0;
    for (std::size_t i = 0; i < ids.size(); ++i) {
        ASSERT_LE(ids[i], patches.size());
        mismatched += merged[i] != ids[i] || merged_depth[i] != depth[i];
    }
    EXPECT_EQ(mismatched, 0u);
    EXPECT_GT(test::ids_present(ids).size(), 100u);
}

TEST(PatchRenderer, DisplacementMovesTheSurface) {
    const std::vector<BezierPatch> patches = teapot_patches();
    PatchRenderer r(test::context());
    r.set_patches(patches);
    const RenderParams params = front_view(patches);
    r.render(params);
    const auto flat_depth = r.read_depth();
    r.set_displacement_map(make_procedural_displacement(64, 0.2f));
    r.render(params);
    const auto bumpy_depth = r.read_depth();
    std::size_t differ = 0;
    for (std::size_t i = 0; i < flat_depth.size(); ++i) differ += flat_depth[i] != bumpy_depth[i];
    EXPECT_GT(differ, flat_depth.size() / 20);
    RenderParams off = params;
    off.displace = false;
    r.render(off);
    EXPECT_EQ(r.read_depth(), flat_depth);
    EXPECT_THROW(r.set_patches(patches, test::margins_only({1.0f})), patchcull::Error);
}
