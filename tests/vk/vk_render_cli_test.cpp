// `render --api vulkan --verify --vk-validation` (vk_renderer.h's CullRenderer on lavapipe with the
// Khronos validation layer and synchronization validation) under the strict id-buffer test: every
// frame has no false cull, only depth ties differ from the unculled reference, no validation
// message, and an indirect frame submits exactly the patches it draws. Every mode (two passes,
// flags and indirect, the fused pass, one pass with each test alone, ptp and ncone, frustum aabb,
// both schemes, the three Vulkan depth conventions) on the default scene (displaced MonsterFrogs)
// and the small city, a world 1e5 units out; the check can fail (aggressive); the frustum and
// back-patch decisions equal the OpenGL pipeline's, and so do the pictures (the same pose, tangent
// patches and tessellation scales, drawn by both APIs); the flags Vulkan cannot take are refused.
#include <gtest/gtest.h>
#include <stb_image.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"
#include "patchcull/core/thread_placement.h"

using namespace patchcull::cli_test;

namespace {

std::string small_city() { return std::string(PATCHCULL_SOURCE_DIR) + "/data/scenes/city_small.json"; }

struct VulkanTotals {
    long frustum = 0, backpatch = 0, occlusion = 0, false_culls = 0, submitted = 0;
};

// `render ARGS --api vulkan --vk-validation --size 96x64 --verify --json`. strict: exit 0 and every
// frame conservative as the header says; otherwise exit 1 (false culls) and the counts only.
VulkanTotals vulkan_render(const std::string& args, bool strict = true) {
    VulkanTotals t;
    const std::string command = "render " + args + " --api vulkan --vk-validation --size 96x64 --verify --json";
    const CliRun r = run(command);
    EXPECT_EQ(r.status, strict ? 0 : 1) << command << "\n" << r.err;
    if (r.out.empty()) return t;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["api"], "vulkan") << command;
    EXPECT_EQ(j["validation_messages"], 0) << command << "\n" << r.err;
    // lavapipe's threads: pinned one CPU each unless --driver-threads os (or one CPU).
    const bool os = args.find("--driver-threads os") != std::string::npos;
    EXPECT_EQ(j["driver_threads"], os ? "os" : "spread") << command;
    if (os || patchcull::thread_cpu_count(static_cast<int>(gettid())) < 2) {
        EXPECT_EQ(j["pinned_driver_threads"], 0) << command;
    } else {
        EXPECT_GT(j["pinned_driver_threads"].get<int>(), 0) << command;
    }
    for (const nlohmann::json& f : j["frames"]) {
        const std::string where = command + ", frame " + f["frame"].dump();
        const long submitted = f["submitted"]["pass1"].get<long>() + f["submitted"]["pass2"].get<long>();
        const long drawn = f["pass1_drawn"].get<long>() + f["pass2_drawn"].get<long>();
        t.frustum += f["frustum_culled"].get<long>();
        t.backpatch += f["backpatch_culled"].get<long>();
        t.occlusion += f["occlusion_culled"].get<long>();
        t.false_culls += f["false_culls"].get<long>();
        t.submitted += submitted;
        if (!strict) continue;
        EXPECT_EQ(f["false_culls"], 0) << where << ": " << f.value("false_culled_patches", nlohmann::json()).dump();
        EXPECT_EQ(f["differing_pixels"], f["depth_ties"]) << where;
        if (j["draw"] == "indirect") {
            EXPECT_EQ(submitted, drawn) << where;
        }
        EXPECT_GT(drawn, 0) << where;
    }
    return t;
}

}  // namespace

// Niessner & Loop's two-pass frame with every test, indirect and flags, fused, in each depth
// convention, on the default scene and the small city.
TEST(VulkanRenderCli, TwoPassFramesVerifyOnTheDefaultSceneAndTheSmallCity) {
    for (const std::string& scene : {std::string("default"), small_city()}) {
        const VulkanTotals all = vulkan_render(scene + " --frames 2 --tess 4");
        EXPECT_GT(all.frustum, 0) << scene;
        EXPECT_GT(all.occlusion, 0) << scene;
        const VulkanTotals flags = vulkan_render(scene + " --frames 2 --tess 4 --draw flags --clip-depth reversed");
        EXPECT_GT(flags.submitted, all.submitted) << scene;  // every patch issued in each pass
        EXPECT_GT(vulkan_render(scene + " --frames 2 --tess 4 --fused-pass --clip-depth reversed-infinite").occlusion,
                  0)
            << scene;
        vulkan_render(scene + " --frames 2 --tess 2 --cull occlusion --compact append --scheme osd");
    }
    EXPECT_GT(vulkan_render("default --frames 2 --tess 4").backpatch, 0);
}

// One pass (no occlusion): each test alone, the back-patch methods, Sathe's box and the displaced
// bounds' other kinds.
TEST(VulkanRenderCli, OnePassFramesAndEveryBackpatchMethodVerify) {
    EXPECT_GT(vulkan_render("default --frames 2 --tess 4 --cull frustum").frustum, 0);
    EXPECT_GT(vulkan_render("default --frames 1 --tess 4 --cull frustum --driver-threads os").frustum, 0);
    EXPECT_GT(vulkan_render("default --frames 1 --tess 4 --cull backpatch --backpatch ptp").backpatch, 0);
    EXPECT_GT(vulkan_render("default --frames 2 --tess 4 --backpatch ncone --fused-pass").backpatch, 0);
    EXPECT_GT(vulkan_render(small_city() + " --frames 2 --tess 2 --frustum aabb --bound oobb --cone con").occlusion, 0);
}

// A world far from the origin (each frame drawn in its camera's frame) and adaptive tessellation.
TEST(VulkanRenderCli, FarWorldAndAdaptiveTessellationVerify) {
    const std::string x = "100000";
    const std::string scene = write_file("vulkan_far_1e5.json", R"({"name": "vulkan_far",
 "displacement": {"map": "procedural", "scale": 0.03, "size": 64},
 "objects": [
  {"model": "bigguy", "transform": {"position": [)" + x + R"(, 0, 0], "yaw_degrees": 200, "height": 1}},
  {"model": "monsterfrog", "transform": {"position": [)" + x + R"(.8, 0, -1.5], "height": 0.7}, "displaced": true}],
 "environment": [
  {"name": "wall", "box": {"min": [)" + x + R"(.3, 0, -1.3], "max": [)" +
                                                                    x + R"(.9, 1.3, -1.1]}}],
 "camera": {"orbit": {"target": [)" + x + R"(, 0.5, -1.2], "distance": 4, "height": 0.8, "start_degrees": 10,
            "degrees_per_frame": 20}, "z_near": 0.05, "z_far": 40}})");
    const VulkanTotals far = vulkan_render(scene + " --frames 3 --tess 4");
    EXPECT_GT(far.occlusion + far.backpatch, 0);
    vulkan_render("bigguy --frames 2 --tess 16 --tess-mode adaptive");
}

// The check can fail: without pass 2 the newly visible patches are missing.
TEST(VulkanRenderCli, AggressiveFramesShowFalseCulls) {
    EXPECT_GT(vulkan_render("default --frames 2 --tess 2 --aggressive", false).false_culls, 0);
}

// The frustum and back-patch decisions do not depend on the API: the same counts as OpenGL's
// pipeline, frame by frame (occlusion differs with the rasterization of the two drivers).
TEST(VulkanRenderCli, FrustumAndBackpatchCountsEqualOpenGLs) {
    const std::string args = "default --frames 2 --tess 4 --size 96x64 --json";
    const CliRun gl = run("render " + args + " --api gl");
    const CliRun vk = run("render " + args + " --api vulkan");
    ASSERT_EQ(gl.status, 0) << gl.err;
    ASSERT_EQ(vk.status, 0) << vk.err;
    const nlohmann::json a = nlohmann::json::parse(gl.out), b = nlohmann::json::parse(vk.out);
    EXPECT_EQ(a["api"], "gl");
    ASSERT_EQ(a["frames"].size(), b["frames"].size());
    for (std::size_t f = 0; f < a["frames"].size(); ++f) {
        EXPECT_EQ(a["frames"][f]["frustum_culled"], b["frames"][f]["frustum_culled"]) << "frame " << f;
        EXPECT_EQ(a["frames"][f]["backpatch_culled"], b["frames"][f]["backpatch_culled"]) << "frame " << f;
    }
}

// The pictures equal OpenGL's up to the rasterizers' rounding: every frame draws the frame's own
// pose with its attributes (a frame drawn with the previous pose's tangent patches, or frame 0
// without its tessellation scales, differs on the animated characters and at patch edges).
TEST(VulkanRenderCli, PicturesEqualOpenGLs) {
    for (const std::string args : {"default --frames 3 --cull none", "bigguy --scheme osd --frames 1 --tess 2"}) {
        std::vector<unsigned char*> images;
        int w = 0, h = 0;
        for (const std::string api : {"gl", "vulkan"}) {
            const std::string png = scratch_dir() + "/picture_" + api + ".png";
            std::string command = "render " + args;
            command += " --size 192x108 --api " + api;
            command += " --out " + png;
            const CliRun r = run(command);
            ASSERT_EQ(r.status, 0) << args << " --api " << api << "\n" << r.err;
            int channels = 0;
            images.push_back(stbi_load(png.c_str(), &w, &h, &channels, 4));
            ASSERT_NE(images.back(), nullptr) << png;
        }
        ASSERT_EQ(w * h, 192 * 108);
        int differing = 0;
        for (int i = 0; i < w * h; ++i)
            for (int c = 0; c < 3; ++c)
                if (std::abs(int(images[0][4 * i + c]) - int(images[1][4 * i + c])) > 8) {
                    ++differing;
                    break;
                }
        EXPECT_LT(differing, w * h / 500) << args;  // under 0.2% of the pixels
        for (unsigned char* image : images) stbi_image_free(image);
    }
}

// What the Vulkan renderer cannot take: one line naming the flag, exit status 2.
TEST(VulkanRenderCli, RefusesWhatItCannotDraw) {
    expect_one_line_error(run("render --api vulkan --clip-depth minus-one-to-one --frames 1"), "--api vulkan");
    expect_one_line_error(run("render --api vulkan --cull auto --frames 1"), "--cull auto");
    expect_one_line_error(run("render --api vulkan --objects bvh --frames 1"), "--objects");
    expect_one_line_error(run("render --api vulkan --pose gpu --frames 1"), "--pose");
    expect_one_line_error(run("render --api vulkan --compact fused --frames 1"), "--compact fused");
    expect_one_line_error(run("render --vk-validation --frames 1"), "--vk-validation");
    expect_one_line_error(run("render --vk-device gpu --frames 1"), "--vk-device");
    expect_one_line_error(run("render --api vulkan --vk-device tpu --frames 1"), "--vk-device");
    expect_one_line_error(run("render --api metal --frames 1"), "--api");
    expect_one_line_error(run("render bigguy --scheme osd --patch-source osd-table --api vulkan --frames 1"), "--api");
}
