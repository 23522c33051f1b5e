// `patchcull render --api vulkan` (render_vulkan.h).
#include "render_vulkan.h"

#include <cstdio>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "patchcull/core/error.h"

#ifdef PATCHCULL_CLI_VULKAN
#include "frame_poser.h"
#include "frame_report.h"
#include "patchcull/eval_gl/reference_frame.h"
#include "patchcull/eval_gl/scene_setup.h"
#include "patchcull/gl/gl_verification.h"
#include "patchcull/import/scene_poser.h"
#include "patchcull/vk/vk_renderer.h"
#include "render_dumps.h"
#include "render_support.h"
#endif

namespace patchcull::cli {

#ifndef PATCHCULL_CLI_VULKAN

int run_vulkan_render(const VulkanRenderJob&) {
    throw Error("--api vulkan: this patchcull was built without Vulkan (configure with -DPATCHCULL_WITH_VULKAN=ON)");
}

#else

namespace {

void upload_occluders(vk::CullRenderer& renderer, const Scene& scene) {
    std::vector<vk::TriangleRange> one_sided;
    for (const EnvironmentObject& e : scene.environment)
        if (e.one_sided && e.triangle_count) one_sided.push_back({e.first_triangle, e.triangle_count});
    renderer.set_occluders(scene.occluder_vertices, scene.occluder_indices, one_sided);
}

gl::FrameCapture as_capture(vk::FrameImages images) {
    gl::FrameCapture c;
    c.ids = std::move(images.ids);
    c.depth = std::move(images.depth);
    c.patches = std::move(images.patches);
    return c;
}

}  // namespace

int run_vulkan_render(const VulkanRenderJob& job) {
    Scene& scene = *job.scene;
    vk::HeadlessDeviceOptions device_options;
    device_options.validation = job.validation;
    if (job.prefer_gpu) device_options.prefer = vk::HeadlessDeviceOptions::Prefer::gpu;
    device_options.driver_threads = job.driver_threads;
    vk::HeadlessDevice device(device_options);
    auto renderer_owner = std::make_unique<vk::CullRenderer>(device);  // destroyed before the last messages
    vk::CullRenderer& renderer = *renderer_owner;
    ScenePoser poser(scene);
    const bool one_sided = eval_gl::scene_is_one_sided(scene);
    // Each pose before its attributes are read (pose_attributes copies the poser's last pose).
    const std::vector<BezierPatch>& first_pose = poser.pose(0.0f);
    renderer.set_patches(first_pose, eval_gl::pose_attributes(poser));
    renderer.set_displacement_map(scene.displacement);
    upload_occluders(renderer, scene);
    auto same = [](DVec3 a, DVec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; };

    nlohmann::json frames = nlohmann::json::array();
    std::size_t total_false = 0, messages = 0;
    for (int f = 0; f < job.frames; ++f) {
        const auto fi = static_cast<std::size_t>(f);
        if (job.world && !same(job.frame_origins[fi], scene.frame_origin)) {
            rebase_scene(*job.world, job.frame_origins[fi], scene);
            upload_occluders(renderer, scene);
        }
        if (f > 0) {
            const std::vector<BezierPatch>& pose = poser.pose(f * kSecondsPerFrame);
            renderer.update_patches(pose, eval_gl::pose_attributes(poser));
        }
        vk::CullFrameParams params;
        params.render = eval_gl::render_params(job.cameras[fi], job.width, job.height, job.tess, one_sided);
        apply_tess_mode(job.tess_mode, params.render);
        params.tests = job.tests;
        params.aggressive = job.aggressive;
        params.backpatch = job.backpatch;
        params.bound = job.bound;
        params.cone = job.cone;
        params.frustum_aabb = job.frustum_aabb;
        params.fused_pass = job.fused_pass;
        params.indirect = job.indirect;
        params.compact = job.scan ? vk::CompactMethod::prefix_scan : vk::CompactMethod::atomic_append;
        const vk::CullFrameStats stats = renderer.render_frame(params);
        const bool last = f + 1 == job.frames;
        if (last && !job.out.empty()) write_png_checked(job.out, job.width, job.height, 4, renderer.read_color());
        std::size_t false_culls = 0, depth_ties = 0, differing_pixels = 0;
        std::vector<std::uint32_t> false_culled;
        if (job.verify) {
            const gl::FrameCapture culled = as_capture(renderer.capture());
            const gl::FrameCapture reference = as_capture(renderer.render_reference(params.render));
            const gl::FrameComparison cmp = gl::compare_frames(reference, culled);
            false_culled = cmp.false_culled;
            false_culls = false_culled.size();
            depth_ties = cmp.depth_ties;
            differing_pixels = cmp.differing_pixels;
        }
        total_false += false_culls;
        const std::vector<std::string> frame_messages = device.take_messages();
        for (const std::string& m : frame_messages) std::fprintf(stderr, "Vulkan validation: %s\n", m.c_str());
        messages += frame_messages.size();
        nlohmann::json frame = frame_counts_json(f, stats);  // the GL run's keys (frame_report.h)
        frame["ms"] = frame_ms_json(stats);
        frame["false_culls"] = false_culls;
        frame["depth_ties"] = depth_ties;
        frame["validation_messages"] = frame_messages.size();
        if (!false_culled.empty()) frame["false_culled_patches"] = false_culled;
        if (job.verify) frame["differing_pixels"] = differing_pixels;
        frames.push_back(frame);
        if (!job.json) {
            print_frame_line(f, stats);
            if (job.verify) std::printf("; false culls %zu", false_culls);
            std::printf("\n");
        }
    }
    renderer_owner.reset();  // what the layer says while the renderer goes counts too
    for (const std::string& m : device.take_messages()) {
        std::fprintf(stderr, "Vulkan validation: %s\n", m.c_str());
        ++messages;
    }
    if (job.json) {
        nlohmann::json out;
        out["api"] = "vulkan";
        out["model"] = scene.name;
        out["patch_source"] = "bezier";
        out["patches"] = scene.patch_count();
        out["size"] = {job.width, job.height};
        out["clip_depth"] = clip_depth_name(job.cameras.empty() ? ClipDepth::zero_to_one : job.cameras[0].depth);
        out["tess"] = job.tess;
        out["tess_mode"] = job.tess_mode.adaptive ? "adaptive" : "uniform";
        out["cull"] = job.cull_name;
        out["backpatch"] = job.backpatch_name;
        out["aggressive"] = job.aggressive;
        out["verified"] = job.verify;
        out["displace"] = scene.displacement_name;
        out["displace_scale"] = scene.displacement.empty() ? 0.0f : scene.displacement.scale;
        out["displaced_patches"] = displaced_patch_count(poser);
        out["bound"] = job.bound_name;
        out["cone"] = job.cone_name;
        out["frustum"] = job.frustum_name;
        out["pose"] = "cpu";
        out["fused_pass"] = job.fused_pass;
        out["draw"] = job.draw_name;
        out["compact"] = job.compact_name;
        out["renderer"] = device.name();
        out["driver_threads"] = driver_threads_name(job.driver_threads);
        out["pinned_driver_threads"] = device.pinned_driver_threads();
        out["validation"] = job.validation;
        out["validation_messages"] = messages;
        out["frames"] = frames;
        out["false_culls"] = total_false;
        std::cout << out.dump() << "\n";
    } else if (job.verify) {
        std::printf("false culls in total: %zu\n", total_false);
    }
    if (messages > 0) std::fprintf(stderr, "Vulkan validation: %zu messages\n", messages);
    return total_false > 0 || messages > 0 ? 1 : 0;
}

#endif

}  // namespace patchcull::cli
