// The occlusion horizon and cells and portals (scene_occlusion.h) on the GPU pipeline: small
// built-in cities and buildings along their camera paths, every frame against the unculled
// render (strict: no patch of the reference's front set left undrawn, no culled occluder triangle
// in its id buffer), alone and followed by the patch passes; and the methods must cull.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_verification.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_occlusion.h"
#include "patchcull/import/scene_poser.h"

namespace patchcull::gl {
namespace {

constexpr float kSecondsPerFrame = 1.0f / 12.0f;

std::size_t culled_triangles_shown(const std::vector<std::uint32_t>& ids, const std::vector<IndexSpan>& culled) {
    std::size_t shown = 0;
    for (std::uint32_t id : ids) {
        if (!(id & kIdOccluderBit)) continue;
        const std::uint32_t t = id & ~kIdOccluderBit;
        for (const IndexSpan& s : culled) shown += t >= s.first && t < s.first + s.count;
    }
    return shown;
}

// Runs `frames` frames of the scene's path with the method after the BVH object level; returns
// the objects it hid over all frames. Every frame must be conservative.
std::size_t run_scene(Scene scene, SceneOcclusionMethod method, int frames, int frame_step, int width, int height) {
    ObjectLevelSetup setup;
    setup.clusters = false;
    SceneObjectLevel level(scene, setup);
    SceneOcclusion occlusion(scene, level, method);
    CullPipeline pipeline(test::context());
    ScenePoser poser(scene);
    pipeline.set_patches(poser.pose(0));
    std::vector<TriangleSpan> one_sided;
    for (const EnvironmentObject& e : scene.environment)
        if (e.one_sided) one_sided.push_back({e.first_triangle, e.triangle_count});
    pipeline.renderer().set_occluders(scene.occluder_vertices, scene.occluder_indices, one_sided);
    const std::vector<Camera> cameras = scene.camera_path(frames * frame_step, float(width) / float(height));
    std::size_t hidden = 0;
    for (CullMode mode : {CullMode::none, CullMode::occlusion}) {
        pipeline.reset_visibility();
        for (int f = 0; f < frames * frame_step; f += frame_step) {
            const float t = float(f) * kSecondsPerFrame;
            const std::vector<BezierPatch>& pose = poser.pose(t);
            pipeline.update_patches(pose);
            const Camera& camera = cameras[static_cast<std::size_t>(f)];
            ObjectCullOptions options;
            options.method = ObjectCullMethod::bvh;
            const ObjectCullResult& result = level.cull(pose, poser.displacement_ranges(), t, camera, height, options);
            const ObjectCullResult& culled = occlusion.cull(result, camera, width, height);
            hidden += occlusion.stats().objects_culled;
            PipelineParams params;
            params.frame.render.view = camera.view();
            params.frame.render.projection = camera.projection();
            params.frame.render.width = width;
            params.frame.render.height = height;
            params.frame.render.tess_level = 2;
            params.frame.cull = mode;
            params.frame.timing = TimingMethod::off;
            for (const IndexSpan& s : culled.culled_patches) params.object_culled.push_back({s.first, s.count});
            for (const IndexSpan& s : culled.culled_triangles) params.culled_occluders.push_back({s.first, s.count});
            pipeline.render_frame(params);
            const FrameCapture frame = {pipeline.renderer().read_ids(), pipeline.renderer().read_depth(),
                                        pipeline.renderer().read_drawn_patches()};
            RenderParams reference_params = params.frame.render;
            reference_params.use_cull_flags = false;
            pipeline.renderer().render(reference_params);
            const FrameCapture reference = {pipeline.renderer().read_ids(), pipeline.renderer().read_depth(),
                                            pipeline.renderer().mark_front_patches(reference_params)};
            const FrameComparison cmp = compare_frames(reference, frame);
            EXPECT_TRUE(cmp.false_culled.empty())
                << scene.name << " " << scene_occlusion_method_name(method) << ", mode " << cull_mode_name(mode)
                << ", frame " << f << ": " << cmp.false_culled.size() << " false culls";
            EXPECT_EQ(culled_triangles_shown(reference.ids, culled.culled_triangles), 0u)
                << scene.name << " frame " << f << ": a culled occluder triangle is in the reference";
        }
    }
    return hidden;
}

TEST(SceneOcclusionGpu, HorizonInASmallCity) {
    CityParams p;
    p.blocks_x = 3;
    p.blocks_z = 4;
    p.characters = 14;
    EXPECT_GT(run_scene(make_city_scene(Scheme::acc, p), SceneOcclusionMethod::horizon, 5, 9, 128, 72), 0u);
}

TEST(SceneOcclusionGpu, PortalsInASmallBuilding) {
    BuildingParams p;
    p.rooms_x = 3;
    p.rooms_z = 3;
    p.characters_per_room = 1;
    EXPECT_GT(run_scene(make_building_scene(Scheme::acc, p), SceneOcclusionMethod::portals, 5, 12, 128, 72), 0u);
}

TEST(SceneOcclusionGpu, HorizonInASmallBuilding) {
    // Walls are closed boxes too: the horizon applies indoors (every wall piece an occluder).
    BuildingParams p;
    p.rooms_x = 3;
    p.rooms_z = 2;
    p.characters_per_room = 1;
    run_scene(make_building_scene(Scheme::acc, p), SceneOcclusionMethod::horizon, 3, 15, 96, 54);
}

}  // namespace
}  // namespace patchcull::gl
