// The GPU side of the object level (gl_pipeline.h PipelineParams::object_culled and
// culled_occluders, gl_renderer.h set_occluders' one-sided spans): spans culled before the passes
// are never drawn, get kCullObject, come back as newly visible; culled occluder triangles leave the
// frame but not the unculled reference; one-sided occluders show nothing from behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_pipeline.h"

namespace patchcull::gl {
namespace {

RenderParams teapot_view(int size) {
    RenderParams rp;
    rp.view = look_at({0, -8, 4}, {0, 0, 1.5f}, {0, 0, 1});
    rp.projection = perspective(0.9f, 1.0f, 0.5f, 40.0f);
    rp.width = rp.height = size;
    rp.tess_level = 2;
    return rp;
}

PipelineParams frame_of(const RenderParams& rp, CullMode mode) {
    PipelineParams p;
    p.frame.render = rp;
    p.frame.cull = mode;
    p.frame.timing = TimingMethod::off;
    return p;
}

bool any_id_of_patches(const std::vector<std::uint32_t>& ids, std::size_t first, std::size_t count) {
    return std::any_of(ids.begin(), ids.end(), [&](std::uint32_t id) {
        return id != 0 && !(id & kIdOccluderBit) && id - 1 >= first && id - 1 < first + count;
    });
}

TEST(ObjectSpans, CulledSpanIsNeverDrawnAndComesBackNewlyVisible) {
    CullPipeline pipeline(test::context());
    const std::vector<BezierPatch> patches = test::split_teapot(1);  // 128 patches
    pipeline.set_patches(patches);
    const RenderParams rp = teapot_view(96);
    for (CullMode mode : {CullMode::none, CullMode::frustum, CullMode::all}) {
        pipeline.reset_visibility();
        PipelineParams p = frame_of(rp, mode);
        p.objects = {{0, 64, true}, {64, 64, true}};
        p.object_culled = {{10, 20}, {90, 5}};
        for (int f = 0; f < 2; ++f) {
            const FrameStats s = pipeline.render_frame(p);
            EXPECT_EQ(s.object_culled, 25u);
            ASSERT_EQ(s.objects.size(), 2u);
            EXPECT_EQ(s.objects[0].object_culled, 20u);
            EXPECT_EQ(s.objects[1].object_culled, 5u);
            EXPECT_EQ(s.objects[0].frustum_culled + s.objects[0].backpatch_culled + s.objects[0].occlusion_culled +
                          s.objects[0].visible + s.objects[0].object_culled,
                      64u);
            const std::vector<std::uint8_t> drawn = pipeline.renderer().read_drawn_patches();
            const std::vector<std::uint32_t> flags = pipeline.renderer().read_cull_flags();
            for (std::size_t i = 10; i < 30; ++i) {
                EXPECT_EQ(drawn[i], 0u) << i;
                EXPECT_EQ(flags[i], kCullObject) << i;
            }
            EXPECT_FALSE(any_id_of_patches(pipeline.renderer().read_ids(), 10, 20));
            EXPECT_FALSE(any_id_of_patches(pipeline.renderer().read_ids(), 90, 5));
        }
        // The spans come back: tested, drawn in the second pass (or the one pass), and the frame
        // equals the unculled render again.
        PipelineParams back = frame_of(rp, mode);
        const FrameStats s = pipeline.render_frame(back);
        EXPECT_EQ(s.object_culled, 0u);
        const std::vector<std::uint32_t> ids = pipeline.renderer().read_ids();
        EXPECT_TRUE(any_id_of_patches(ids, 10, 20)) << cull_mode_name(mode);
        if (mode == CullMode::all) {
            EXPECT_GE(s.newly_visible, 1u);
        }
        RenderParams reference = rp;
        reference.use_cull_flags = false;
        pipeline.renderer().render(reference);
        EXPECT_EQ(pipeline.renderer().read_ids(), ids) << cull_mode_name(mode);
    }
}

TEST(ObjectSpans, BadSpansAreRefused) {
    CullPipeline pipeline(test::context());
    pipeline.set_patches(test::split_teapot(0));  // 32 patches
    PipelineParams p = frame_of(teapot_view(32), CullMode::frustum);
    p.object_culled = {{30, 3}};
    EXPECT_THROW(pipeline.render_frame(p), Error);
    p.object_culled = {{0, 4}, {3, 2}};
    EXPECT_THROW(pipeline.render_frame(p), Error);
    p.object_culled = {};
    p.culled_occluders = {{0, 1}};  // no occluders
    EXPECT_THROW(pipeline.render_frame(p), Error);
    EXPECT_THROW(pipeline.renderer().draw_selected(0, 0, {{31, 2}}), Error);
}

// A unit box, CCW outward (two triangles per face), at the origin.
void unit_box(std::vector<Vec3>& v, std::vector<std::uint32_t>& idx, Vec3 lo, Vec3 hi) {
    const auto base = static_cast<std::uint32_t>(v.size());
    for (int i = 0; i < 8; ++i) v.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
    const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& q : quads)
        for (int k : {0, 1, 2, 0, 2, 3}) idx.push_back(base + q[k]);
}

TEST(ObjectSpans, OneSidedOccludersShowOnlyTheirFront) {
    PatchRenderer r(test::context());
    r.set_patches(std::vector<BezierPatch>{});
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    unit_box(v, idx, {-1, -1, -1}, {1, 1, 1});
    RenderParams rp;
    rp.view = look_at({0.3f, -5, 0.7f}, {0, 0, 0}, {0, 0, 1});
    rp.projection = perspective(0.8f, 1.0f, 0.5f, 20.0f);
    rp.width = rp.height = 64;
    // Two-sided: from outside the near faces win; the back faces are hidden.
    r.set_occluders(v, idx);
    r.render(rp);
    const std::vector<std::uint32_t> two_sided = r.read_ids();
    r.set_occluders(v, idx, {{0, 12}});
    r.render(rp);
    EXPECT_EQ(r.read_ids(), two_sided);  // a closed outward box looks the same one-sided
    // From inside, one-sided shows nothing (every face is seen from behind), two-sided shows walls.
    RenderParams inside = rp;
    inside.view = look_at({0, 0, 0}, {0, 1, 0}, {0, 0, 1});
    inside.projection = perspective(0.8f, 1.0f, 0.05f, 20.0f);
    r.render(inside);
    for (std::uint32_t id : r.read_ids()) EXPECT_EQ(id, 0u);
    r.set_occluders(v, idx);
    r.render(inside);
    const std::vector<std::uint32_t> walls = r.read_ids();
    EXPECT_TRUE(std::any_of(walls.begin(), walls.end(), [](std::uint32_t id) { return id != 0; }));
    EXPECT_THROW(r.set_occluders(v, idx, {{10, 3}}), Error);
}

TEST(ObjectSpans, CulledOccludersLeaveTheFrameNotTheReference) {
    PatchRenderer r(test::context());
    r.set_patches(std::vector<BezierPatch>{});
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    unit_box(v, idx, {-2, -1, -1}, {-0.5f, 1, 1});  // triangles 0-11
    unit_box(v, idx, {0.5f, -1, -1}, {2, 1, 1});    // triangles 12-23
    r.set_occluders(v, idx, {{0, 24}});
    RenderParams rp;
    rp.view = look_at({0, -8, 0.5f}, {0, 0, 0}, {0, 0, 1});
    rp.projection = perspective(0.9f, 1.0f, 0.5f, 20.0f);
    rp.width = rp.height = 64;
    auto boxes_seen = [&](const std::vector<std::uint32_t>& ids) {
        bool first = false, second = false;
        for (std::uint32_t id : ids) {
            if (!(id & kIdOccluderBit)) continue;
            ((id & ~kIdOccluderBit) < 12 ? first : second) = true;
        }
        return std::make_pair(first, second);
    };
    r.set_culled_occluders({{12, 12}});
    r.render(rp);  // use_cull_flags: the culled box is skipped
    EXPECT_EQ(boxes_seen(r.read_ids()), std::make_pair(true, false));
    rp.use_cull_flags = false;
    r.render(rp);  // the unculled reference draws both
    EXPECT_EQ(boxes_seen(r.read_ids()), std::make_pair(true, true));
    r.set_culled_occluders({});
    rp.use_cull_flags = true;
    r.render(rp);
    EXPECT_EQ(boxes_seen(r.read_ids()), std::make_pair(true, true));
    EXPECT_THROW(r.set_culled_occluders({{20, 5}}), Error);
}

}  // namespace
}  // namespace patchcull::gl
