// The GPU Hi-Z pipeline against its CPU mirror (include/patchcull/core/hiz.h): on the same depth buffer
// (rendered by GL, read back) the compute-built pyramid (shaders/hiz_build.comp.glsl) is
// bit-identical to HiZPyramid::build, and the combined cull pass (shaders/occlusion.comp.glsl, OcclusionPass)
// makes the same decisions as cull_occlusion_scalar, patch by patch, on the same matrix: the teapot
// with triangle occluders from several cameras, random (rational, eye-straddling) patches, and
// NPOT / odd framebuffer sizes.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/hiz.h"
#include "shared.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

Camera teapot_camera(const Bounds& b, Vec3 direction, float distance, float aspect = 1.0f) {
    Camera cam;
    cam.target = b.center();
    cam.eye = b.center() + normalize(direction) * (distance * b.radius());
    cam.up = {0, 0, 1};
    cam.aspect = aspect;
    cam.z_near = 0.05f * b.radius();
    cam.z_far = 12.0f * b.radius();
    return cam;
}

RenderParams params_for(const Camera& cam, int width, int height, int level = 6) {
    RenderParams p;
    p.view = cam.view();
    p.projection = cam.projection();
    p.width = width;
    p.height = height;
    p.tess_level = level;
    return p;
}

// A vertical wall quad through point `at`, facing direction `normal` (horizontal), half-extents
// half_w (horizontal) and from z0 to z1.
void add_wall(std::vector<Vec3>& v, std::vector<std::uint32_t>& idx, Vec3 at, Vec3 normal, float half_w, float z0,
              float z1) {
    const Vec3 side = normalize(cross(Vec3{0, 0, 1}, normal)) * half_w;
    const auto base = static_cast<std::uint32_t>(v.size());
    v.push_back(Vec3{at.x, at.y, z0} - side);
    v.push_back(Vec3{at.x, at.y, z0} + side);
    v.push_back(Vec3{at.x, at.y, z1} + side);
    v.push_back(Vec3{at.x, at.y, z1} - side);
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) idx.push_back(base + i);
}

// The GPU pyramid of a renderer's last frame: HiZBuildPass on its depth texture into a texture of
// the framebuffer's size (recreated when the size changes).
class GpuPyramid {
public:
    ~GpuPyramid() { release(); }
    const HiZTexture& build(PatchRenderer& r) {
        if (hiz_.width != r.width() || hiz_.height != r.height()) {
            release();
            hiz_ = create_hiz_texture(r.width(), r.height());
        }
        pass_.run(r.depth_texture(), hiz_);
        return hiz_;
    }
    const HiZTexture& texture() const { return hiz_; }

private:
    void release() {
        if (hiz_.texture) glDeleteTextures(1, &hiz_.texture);
        hiz_ = {};
    }
    HiZBuildPass pass_{test::passes()};
    HiZTexture hiz_;
};

GpuPyramid& gpu_pyramid() {
    static GpuPyramid p;
    return p;
}

// Compares the GPU pyramid with the CPU one built from the read-back depth; returns the CPU one.
HiZPyramid check_pyramid(PatchRenderer& r, const char* what) {
    const std::vector<float> depth = r.read_depth_bottom_up();
    HiZPyramid cpu;
    cpu.build(depth.data(), r.width(), r.height());
    const std::vector<float> gpu = read_hiz_texture(gpu_pyramid().build(r));
    EXPECT_EQ(HiZPyramid::level_count(r.width(), r.height()), cpu.levels()) << what;
    EXPECT_EQ(gpu.size(), cpu.size()) << what;
    if (gpu.size() == cpu.size()) {
        std::size_t differ = 0;
        for (std::size_t i = 0; i < gpu.size(); ++i) {
            std::uint32_t a, b;
            std::memcpy(&a, &gpu[i], 4);
            std::memcpy(&b, &cpu.data()[i], 4);
            differ += a != b;
        }
        EXPECT_EQ(differ, 0u) << what << ": texels differing from HiZPyramid::build";
    }
    return cpu;
}

struct DecisionCounts {
    std::size_t frustum = 0, occluded = 0, visible = 0, mismatched = 0;
};

// OcclusionPass (with the frustum test, as the CPU kernel) in a chain of its own on the renderer's
// buffers, statuses updated, vs cull_occlusion_scalar on the same pyramid and matrix.
DecisionCounts compare_decisions(PatchRenderer& r, const std::vector<BezierPatch>& patches, const Mat4& m,
                                 const HiZPyramid& cpu_hiz, const char* what,
                                 ClipDepth depth = ClipDepth::zero_to_one) {
    const PatchBatch batch = make_batch(patches);
    std::vector<std::uint8_t> cpu(patches.size(), 0xEE);
    cull_occlusion_scalar(batch.view(), m, depth, cpu_hiz, cpu.data());
    static CullStatusPass status(test::passes());
    static OcclusionPass occlusion(test::passes());
    status.begin(r.patch_buffers());
    occlusion.run(r.patch_buffers(), m, depth, gpu_pyramid().texture(), true);
    status.end(r.patch_buffers(), 0);
    const std::vector<std::uint32_t> words = r.read_cull_flags();
    DecisionCounts n;
    for (std::size_t p = 0; p < patches.size(); ++p) {
        const std::uint32_t reason = words[p] & kCullReasonMask;
        std::uint8_t gpu = 0xFF;
        if (reason == 0) gpu = kHiZVisible;
        if (reason == kCullFrustum) gpu = kHiZFrustumCulled;
        if (reason == kCullOcclusion) gpu = kHiZOccluded;
        if (gpu != cpu[p]) {
            if (++n.mismatched <= 5)
                ADD_FAILURE() << what << ": patch " << p << " GPU " << int(gpu) << " CPU " << int(cpu[p]);
        }
        EXPECT_EQ((words[p] & kStatusVisible) != 0, reason == 0) << what << " patch " << p;
        n.frustum += cpu[p] == kHiZFrustumCulled;
        n.occluded += cpu[p] == kHiZOccluded;
        n.visible += cpu[p] == kHiZVisible;
    }
    return n;
}

}  // namespace

TEST(GpuHiZ, PyramidBitIdenticalToCpuAtPotAndNpotSizes) {
    const std::vector<BezierPatch> patches = test::split_teapot(1);
    const Bounds b = test::control_point_bounds(patches);
    PatchRenderer r(test::context());
    r.set_patches(patches);
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    add_wall(v, idx, b.center() + Vec3{0.6f * b.radius(), -0.5f * b.radius(), 0}, {0.3f, -1, 0}, 0.4f * b.radius(),
             b.min.z - 1, b.center().z + 0.2f * b.radius());
    r.set_occluders(v, idx);
    const int sizes[][2] = {{256, 256}, {200, 120}, {257, 130}, {97, 255}, {33, 1}, {1, 1}, {5, 3}};
    for (const auto& s : sizes) {
        const Camera cam = teapot_camera(b, {0.4f, -1, 0.45f}, 2.2f, float(s[0]) / float(s[1]));
        r.render(params_for(cam, s[0], s[1], 4));
        const std::string what = std::to_string(s[0]) + "x" + std::to_string(s[1]);
        check_pyramid(r, what.c_str());
    }
    // The pass samples the depth texture through its own sampler and leaves sampler 0 bound there.
    GLint active = 0, sampler = -1;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    glActiveTexture(GL_TEXTURE0 + shared::kTextureUnitDepth);
    glGetIntegerv(GL_SAMPLER_BINDING, &sampler);
    glActiveTexture(static_cast<GLenum>(active));
    EXPECT_EQ(sampler, 0);
}

TEST(GpuHiZ, DecisionsEqualCpuOnTeapotWithOccluders) {
    const std::vector<BezierPatch> patches = test::split_teapot(2);
    const Bounds b = test::control_point_bounds(patches);
    PatchRenderer r(test::context());
    r.set_patches(patches);
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    add_wall(v, idx, b.center() + Vec3{0, -1.1f * b.radius(), 0}, {0, -1, 0}, 0.35f * b.radius(), b.min.z - 1,
             b.max.z + 0.2f);
    r.set_occluders(v, idx);
    const Vec3 dirs[] = {{0.3f, -1, 0.4f}, {1, 0.2f, 0.1f}, {0, 0.1f, 1}, {-0.7f, 0.5f, -0.3f}, {0.1f, -1, 0.05f}};
    const float dists[] = {2.0f, 1.6f, 2.5f, 0.9f, 3.0f};
    DecisionCounts total;
    for (int c = 0; c < 5; ++c) {
        const Camera cam = teapot_camera(b, dirs[c], dists[c]);
        RenderParams params = params_for(cam, 256, 256);
        // Depth of the even-indexed patches only (like a first pass), so that many patches are
        // tested against a partial buffer; then every patch.
        for (int partial = 1; partial >= 0; --partial) {
            std::vector<std::uint8_t> culled(patches.size(), 0);
            if (partial)
                for (std::size_t p = 1; p < patches.size(); p += 2) culled[p] = 1;
            r.set_cull_flags(culled.data());
            r.render(params);
            const std::string what = "camera " + std::to_string(c) + (partial ? " partial" : " full");
            const HiZPyramid cpu = check_pyramid(r, what.c_str());
            const DecisionCounts n = compare_decisions(r, patches, cam.view_projection(), cpu, what.c_str());
            EXPECT_EQ(n.mismatched, 0u) << what;
            total.frustum += n.frustum;
            total.occluded += n.occluded;
            total.visible += n.visible;
        }
    }
    // The cameras exercise every outcome.
    EXPECT_GT(total.frustum, 50u);
    EXPECT_GT(total.occluded, 500u);
    EXPECT_GT(total.visible, 500u);
}

TEST(GpuHiZ, DecisionsEqualCpuOnRandomPatches) {
    // Random (a third rational) patches of random sizes around random cameras, some straddling the
    // eye plane (w <= 0: never screen-tested), some beyond the far plane; the depth buffer is that
    // of a random half of them. Odd framebuffer sizes.
    std::mt19937 rng(20240611);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    auto range = [&](float lo, float hi) { return lo + (hi - lo) * u01(rng); };
    PatchRenderer r(test::context());
    DecisionCounts total;
    const int sizes[][2] = {{256, 256}, {203, 150}, {120, 250}};
    for (int round = 0; round < 6; ++round) {
        Camera cam;
        cam.eye = {range(-2, 2), range(-2, 2), range(-2, 2)};
        cam.target = {range(-0.5f, 0.5f), range(-0.5f, 0.5f), range(-0.5f, 0.5f)};
        cam.up = normalize(Vec3{range(-1, 1), range(-1, 1), range(-1, 1)});
        cam.fovy_radians = range(0.5f, 1.6f);
        cam.z_near = range(0.02f, 0.3f);
        cam.z_far = cam.z_near + range(3.0f, 12.0f);
        const int w = sizes[round % 3][0], h = sizes[round % 3][1];
        cam.aspect = float(w) / float(h);
        const Vec3 forward = normalize(cam.target - cam.eye);
        std::vector<BezierPatch> patches;
        for (int p = 0; p < 600; ++p) {
            // Mostly in front of the camera, some around and behind it.
            const float along = p % 10 == 0 ? range(-1.0f, 0.5f) : range(0.2f, 8.0f);
            const Vec3 centre = cam.eye + forward * along +
                                Vec3{range(-1, 1), range(-1, 1), range(-1, 1)} * (0.2f + 0.6f * std::fabs(along));
            const float size = std::pow(10.0f, range(-2.0f, -0.2f));
            const bool rational = p % 3 == 0;
            // A bumpy sheet (a real surface, so that it writes depth) with random orientation.
            const Vec3 a = normalize(Vec3{range(-1, 1), range(-1, 1), range(-1, 1)});
            const Vec3 bdir = normalize(cross(a, Vec3{range(-1, 1), range(-1, 1), range(-1, 1)}));
            const Vec3 n = cross(a, bdir);
            BezierPatch patch;
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i) {
                    const Vec3 x = centre + a * (size * (i / 1.5f - 1)) + bdir * (size * (j / 1.5f - 1)) +
                                   n * (size * range(-0.3f, 0.3f));
                    patch.cp[4 * j + i] = homogeneous(x, rational ? std::pow(2.0f, range(-1.5f, 1.5f)) : 1.0f);
                }
            patches.push_back(patch);
        }
        r.set_patches(patches);
        std::vector<std::uint8_t> culled(patches.size(), 0);
        for (auto& c : culled) c = u01(rng) < 0.5f;
        r.set_cull_flags(culled.data());
        RenderParams params = params_for(cam, w, h, 5);
        r.render(params);
        const std::string what = "round " + std::to_string(round);
        const HiZPyramid cpu = check_pyramid(r, what.c_str());
        const DecisionCounts n = compare_decisions(r, patches, cam.view_projection(), cpu, what.c_str());
        EXPECT_EQ(n.mismatched, 0u) << what;
        // The same camera as a standard OpenGL (-1..1) matrix: converted like the CPU kernel.
        const Mat4 gl_matrix =
            perspective(cam.fovy_radians, cam.aspect, cam.z_near, cam.z_far, ClipDepth::minus_one_to_one) * cam.view();
        const DecisionCounts g =
            compare_decisions(r, patches, gl_matrix, cpu, (what + " (-1..1)").c_str(), ClipDepth::minus_one_to_one);
        EXPECT_EQ(g.mismatched, 0u) << what << " (-1..1)";
        total.frustum += n.frustum;
        total.occluded += n.occluded;
        total.visible += n.visible;
    }
    EXPECT_GT(total.frustum, 100u);
    EXPECT_GT(total.occluded, 100u);
    EXPECT_GT(total.visible, 100u);
}

TEST(GpuHiZ, PassesRefuseMissingPyramidsAndBadSizes) {
    PatchRenderer r(test::context());
    r.set_patches(teapot_patches());
    RenderParams p =
        params_for(teapot_camera(test::control_point_bounds(teapot_patches()), {0, -1, 0.3f}, 2.5f), 64, 64);
    r.render(p);
    OcclusionPass occlusion(test::passes());
    HiZBuildPass build(test::passes());
    EXPECT_THROW(occlusion.run(r.patch_buffers(), p.projection * p.view, ClipDepth::zero_to_one, HiZTexture{}),
                 patchcull::Error);
    EXPECT_THROW(read_hiz_texture(HiZTexture{}), patchcull::Error);
    EXPECT_THROW(create_hiz_texture(0, 64), patchcull::Error);
    EXPECT_THROW(create_hiz_texture(64, 8193), patchcull::Error);
    HiZTexture hiz = create_hiz_texture(64, 64);
    EXPECT_THROW(build.run(0, hiz), patchcull::Error);  // no depth texture
    build.run(r.depth_texture(), hiz);
    EXPECT_NO_THROW(occlusion.run(r.patch_buffers(), p.projection * p.view, ClipDepth::zero_to_one, hiz));
    EXPECT_EQ(read_hiz_texture(hiz).size(), HiZPyramid(64, 64).size());
    // A flag buffer too small for the range is refused, not overrun.
    PatchBuffers past_the_end = r.patch_buffers();
    past_the_end.first = 1;
    EXPECT_THROW(occlusion.run(past_the_end, p.projection * p.view, ClipDepth::zero_to_one, hiz), patchcull::Error);
    // A GL error the caller left pending is reported as such, not blamed on the pass.
    glBindBuffer(GL_ARRAY_BUFFER, 0xFFFFFFu);  // not a buffer name: GL_INVALID_OPERATION
    try {
        occlusion.run(r.patch_buffers(), p.projection * p.view, ClipDepth::zero_to_one, hiz);
        ADD_FAILURE() << "a pending GL error was not reported";
    } catch (const patchcull::Error& e) {
        EXPECT_NE(std::string(e.what()).find("pending before OcclusionPass"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(occlusion.run(r.patch_buffers(), p.projection * p.view, ClipDepth::zero_to_one, hiz));
    glDeleteTextures(1, &hiz.texture);
}
