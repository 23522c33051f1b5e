// The Vulkan passes against their OpenGL twins and the CPU scalar kernels on the same inputs, in
// one process (lavapipe with the validation layers, llvmpipe on a headless EGL context): the
// chain begin -> frustum -> end leaves the same flag words and counters on both APIs, equal to
// cull_frustum_scalar's decisions, and the frustum pass's six plane maxima are bit-identical, in
// every ClipDepth convention, with and without margins; the frustum-disp, tcone, ncone and ptp
// passes leave the same words on both APIs, equal to their CPU scalar kernels'; the compaction
// pass writes the same list (the scan's order), commands and draw count; from the same depths
// the Hi-Z pyramids are bit-identical and the occlusion and fused passes leave the same words.
// Built only with PATCHCULL_WITH_GL.
#include <gtest/gtest.h>

#if PATCHCULL_VK_TEST_GL

#include <epoxy/gl.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <random>

#include "core/test_patches.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/teapot.h"
#include "patchcull/gl/gl_compaction.h"
#include "patchcull/gl/gl_context.h"
#include "patchcull/gl/gl_passes.h"
#include "shared.h"
#include "vk/vk_cases.h"
#include "vk/vk_images.h"

using namespace patchcull;
using namespace patchcull::vk::test;
namespace shared = patchcull::gl::shared;

namespace {

gl::GlContext& gl_context() {
    static gl::GlContext context = gl::GlContext::create_headless();
    return context;
}

gl::PassContext& gl_passes() {
    gl_context().make_current();
    static gl::PassContext passes;
    return passes;
}

GLuint gl_buffer(std::size_t bytes, const void* data) {
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferData(b, static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)), nullptr, GL_DYNAMIC_DRAW);
    if (data)
        glNamedBufferSubData(b, 0, static_cast<GLsizeiptr>(bytes), data);
    else {
        const std::vector<std::uint8_t> zeros(std::max<std::size_t>(bytes, 16), 0);
        glNamedBufferSubData(b, 0, static_cast<GLsizeiptr>(zeros.size()), zeros.data());
    }
    return b;
}

template <class T>
std::vector<T> gl_read(GLuint buffer, std::size_t count) {
    std::vector<T> out(count);
    glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(count * sizeof(T)), out.data());
    return out;
}

struct ChainResult {
    std::vector<std::uint32_t> words;
    std::vector<float> plane_values;
    std::vector<std::uint32_t> counters;
};

// The frame's chain on GL: begin, frustum, end with counters.
ChainResult gl_chain(const RandomCase& c, const FrustumPlanes& planes, const std::vector<std::uint32_t>& words) {
    gl::PassContext& passes = gl_passes();
    const std::size_t n = c.patches.size();
    gl::PatchBuffers b;
    b.control_points = gl_buffer(n * sizeof(BezierPatch), c.patches.data());
    b.flags = gl_buffer(n * 4, words.data());
    if (!c.margins.empty()) b.margins = gl_buffer(n * 4, c.margins.data());
    b.count = n;
    const GLuint values = gl_buffer(n * 6 * sizeof(float), nullptr);
    const GLuint counters = gl_buffer(shared::kCounterCount * 4, nullptr);
    gl::CullStatusPass status(passes);
    gl::FrustumPass frustum(passes);
    status.begin(b);
    frustum.run(b, planes, values);
    status.end(b, counters);
    ChainResult r{gl_read<std::uint32_t>(b.flags, n), gl_read<float>(values, 6 * n),
                  gl_read<std::uint32_t>(counters, shared::kCounterCount)};
    const GLuint names[] = {b.control_points, b.flags, b.margins, values, counters};
    glDeleteBuffers(5, names);
    return r;
}

// The same chain on Vulkan.
ChainResult vk_chain(Context& vk, const RandomCase& c, const FrustumPlanes& planes,
                     const std::vector<std::uint32_t>& words) {
    const std::size_t n = c.patches.size();
    CaseBuffers b(c);
    b.flags.write(words.data(), n * 4);
    HostBuffer values(n * 6 * sizeof(float));
    HostBuffer counters(shared::kCounterCount * 4);
    vk::CullStatusPass status(vk.passes());
    vk::FrustumPass frustum(vk.passes());
    vk.submit([&](VkCommandBuffer cmd) {
        status.begin(cmd, b.patch_buffers());
        frustum.run(cmd, b.patch_buffers(), planes, values.range());
        status.end(cmd, b.patch_buffers(), counters.range());
    });
    return {b.flags.read<std::uint32_t>(n), values.read<float>(6 * n),
            counters.read<std::uint32_t>(shared::kCounterCount)};
}

// begin -> one test pass on GL buffers holding the case (words with no reason); the flag words.
std::vector<std::uint32_t> gl_words(const RandomCase& c, const std::function<void(const gl::PatchBuffers&)>& run) {
    gl_context().make_current();
    const std::size_t n = c.patches.size();
    gl::PatchBuffers b;
    b.control_points = gl_buffer(n * sizeof(BezierPatch), c.patches.data());
    b.flags = gl_buffer(n * 4, nullptr);
    if (!c.margins.empty()) b.margins = gl_buffer(n * 4, c.margins.data());
    b.count = n;
    gl::CullStatusPass status(gl_passes());
    status.begin(b);
    run(b);
    std::vector<std::uint32_t> words = gl_read<std::uint32_t>(b.flags, n);
    const GLuint names[] = {b.control_points, b.flags, b.margins};
    glDeleteBuffers(3, names);
    return words;
}

// The same on Vulkan.
std::vector<std::uint32_t> vk_words(Context& vk, const RandomCase& c,
                                    const std::function<void(VkCommandBuffer, const vk::PatchBuffers&)>& record) {
    CaseBuffers b(c);
    vk::CullStatusPass status(vk.passes());
    vk.submit([&](VkCommandBuffer cmd) {
        status.begin(cmd, b.patch_buffers());
        record(cmd, b.patch_buffers());
    });
    return b.flags.read<std::uint32_t>(c.patches.size());
}

// The teapot split twice and its originals, a third rational, seen from a random eye.
RandomCase teapot_case(std::uint32_t seed) {
    RandomCase c;
    c.patches = test_patches::split_teapot(2);
    for (const BezierPatch& p : teapot_patches()) c.patches.push_back(p);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> w(0.5f, 2.0f), u(-1.0f, 1.0f);
    for (std::size_t p = 0; p < c.patches.size(); p += 3)
        for (Vec4& cp : c.patches[p].cp) {
            const float k = w(rng);
            cp = {cp.x * k, cp.y * k, cp.z * k, k};
        }
    c.camera.eye = Vec3{u(rng), u(rng), u(rng)} * 6.0f;
    c.camera.target = {0, 0, 1};
    return c;
}

class VkGlEquality : public VkTest {};

}  // namespace

TEST_F(VkGlEquality, FrustumChainWordsEqualGlAndCpuInEveryConvention) {
    std::size_t culled = 0, total = 0;
    for (const ClipDepth depth :
         {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed, ClipDepth::reversed_infinite})
        for (std::uint32_t seed = 21; seed <= 22; ++seed) {
            const RandomCase c = random_case(seed, 1500, depth, seed % 2 == 1);
            const FrustumPlanes planes = make_frustum_planes(c.camera.view_projection(), depth);
            // Last frame's statuses of every kind, and stale reasons that begin clears.
            std::vector<std::uint32_t> words(c.patches.size());
            for (std::size_t p = 0; p < words.size(); ++p)
                words[p] = (p % 3 == 0 ? kStatusVisible : 0u) | (p % 5 == 0 ? kCullBackPatch : 0u);
            const ChainResult on_gl = gl_chain(c, planes, words);
            const ChainResult on_vk = vk_chain(vk(), c, planes, words);
            const std::vector<std::uint32_t> cpu = cpu_frustum_words(c, planes);
            const std::string where = std::string(clip_depth_name(depth)) + " seed " + std::to_string(seed);
            ASSERT_EQ(on_vk.words.size(), on_gl.words.size());
            for (std::size_t p = 0; p < cpu.size(); ++p) {
                ASSERT_EQ(on_vk.words[p], on_gl.words[p]) << where << " patch " << p;
                // The CPU kernel's decision, and the status end gives an uncull one.
                const bool was_visible = (words[p] & kStatusVisible) != 0;
                const std::uint32_t expected =
                    cpu[p] ? cpu[p] : kStatusVisible | (was_visible ? 0u : kStatusNewlyVisible);
                ASSERT_EQ(on_vk.words[p], expected) << where << " patch " << p;
                culled += cpu[p] != 0;
            }
            total += cpu.size();
            EXPECT_EQ(on_vk.counters, on_gl.counters) << where;
            ASSERT_EQ(on_vk.plane_values.size(), on_gl.plane_values.size());
            EXPECT_EQ(std::memcmp(on_vk.plane_values.data(), on_gl.plane_values.data(), on_vk.plane_values.size() * 4),
                      0)
                << where;
        }
    EXPECT_GT(culled, total / 10);
    EXPECT_LT(culled, total * 9 / 10);
}

TEST_F(VkGlEquality, FrustumDispConeAndPtpWordsEqualGlAndCpu) {
    // frustum-disp in every convention, with margins.
    for (const ClipDepth depth :
         {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed, ClipDepth::reversed_infinite}) {
        const RandomCase c = random_case(41, 1500, depth, true);
        const Mat4 m = c.camera.view_projection();
        gl::FrustumDispPass gl_pass(gl_passes());
        vk::FrustumDispPass vk_pass(vk().passes());
        const std::vector<std::uint32_t> on_gl =
            gl_words(c, [&](const gl::PatchBuffers& b) { gl_pass.run(b, m, depth); });
        const std::vector<std::uint32_t> on_vk =
            vk_words(vk(), c, [&](VkCommandBuffer cmd, const vk::PatchBuffers& b) { vk_pass.run(cmd, b, m, depth); });
        std::vector<std::uint8_t> cpu(c.patches.size());
        cull_frustum_disp_scalar(patch_batch(c.patches).view(), c.margins.data(), m, depth, cpu.data());
        EXPECT_EQ(on_vk, on_gl) << "frustum-disp " << clip_depth_name(depth);
        EXPECT_EQ(on_vk, words_of(cpu, kCullFrustum)) << "frustum-disp " << clip_depth_name(depth);
    }
    // tcone and ncone, ptp with both rules.
    const RandomCase c = teapot_case(3);
    const Vec3 eye = c.camera.eye;
    const PatchBatch batch = patch_batch(c.patches);
    for (const BackpatchMethod method : {BackpatchMethod::tcone, BackpatchMethod::ncone}) {
        gl::BackpatchConePass gl_pass(gl_passes());
        vk::BackpatchConePass vk_pass(vk().passes());
        const std::vector<std::uint32_t> on_gl =
            gl_words(c, [&](const gl::PatchBuffers& b) { gl_pass.run(b, method, eye); });
        const std::vector<std::uint32_t> on_vk = vk_words(
            vk(), c, [&](VkCommandBuffer cmd, const vk::PatchBuffers& b) { vk_pass.run(cmd, b, method, eye); });
        std::vector<std::uint8_t> cpu(c.patches.size());
        if (method == BackpatchMethod::tcone)
            cull_tcone_scalar(batch.view(), eye, cpu.data());
        else
            cull_ncone_scalar(batch.view(), eye, cpu.data());
        EXPECT_EQ(on_vk, on_gl) << backpatch_method_name(method);
        EXPECT_EQ(on_vk, words_of(cpu, kCullBackPatch)) << backpatch_method_name(method);
    }
    const Mat4 projection = c.camera.projection();
    const Mat4 m = projection * c.camera.view();
    const float alpha = clip_space_eye_alpha(projection);
    for (const PtpRule rule : {PtpRule::ncnt, PtpRule::pcnt}) {
        gl::BackpatchPtpPass gl_pass(gl_passes());
        vk::BackpatchPtpPass vk_pass(vk().passes());
        const std::vector<std::uint32_t> on_gl =
            gl_words(c, [&](const gl::PatchBuffers& b) { EXPECT_TRUE(gl_pass.run(b, m, alpha, rule)); });
        const std::vector<std::uint32_t> on_vk = vk_words(vk(), c, [&](VkCommandBuffer cmd, const vk::PatchBuffers& b) {
            EXPECT_TRUE(vk_pass.run(cmd, b, m, alpha, rule));
        });
        std::vector<std::uint8_t> cpu(c.patches.size());
        cull_ptp_scalar(batch.view(), m, alpha, rule, cpu.data());
        EXPECT_EQ(on_vk, on_gl) << "ptp " << static_cast<int>(rule);
        EXPECT_EQ(on_vk, words_of(cpu, kCullBackPatch)) << "ptp " << static_cast<int>(rule);
    }
}

TEST_F(VkGlEquality, CompactionWritesTheSameListCommandsAndCount) {
    std::mt19937 rng(8);
    const std::size_t n = 6000, first = 5, count = 5900, list_first = 3, k = 500;
    std::vector<std::uint32_t> words(n);
    for (std::uint32_t& w : words) w = rng() % 3 == 0 ? kCullOcclusion : (rng() % 2 ? kStatusVisible : 0u);
    const std::size_t commands = vk::compact_command_count(count, k);
    ASSERT_EQ(commands, gl::compact_command_count(count, k));
    // GL.
    gl_passes();
    gl::PatchBuffers gb;
    gb.flags = gl_buffer(n * 4, words.data());
    gb.first = first;
    gb.count = count;
    gl::DrawListBuffers gout;
    gout.list = gl_buffer((list_first + count) * 4, nullptr);
    gout.list_first = list_first;
    gout.command = gl_buffer(commands * 16, nullptr);
    gout.draw_count = gl_buffer(4, nullptr);
    gout.patches_per_command = k;
    gl::CompactPass gl_pass(gl_passes());
    gl_pass.run(gb, shared::kDrawMaskUnculled, shared::kDrawValueUnculled, gout, gl::CompactMethod::prefix_scan);
    const std::vector<std::uint32_t> gl_list = gl_read<std::uint32_t>(gout.list, list_first + count);
    const std::vector<std::uint32_t> gl_commands = gl_read<std::uint32_t>(gout.command, commands * 4);
    const std::uint32_t gl_count = gl_read<std::uint32_t>(gout.draw_count, 1)[0];
    const GLuint names[] = {gb.flags, gout.list, gout.command, gout.draw_count};
    glDeleteBuffers(4, names);
    // Vulkan.
    HostBuffer flags(n * 4), list((list_first + count) * 4), command(commands * 16), draw_count(4),
        scratch(vk::compact_scratch_bytes(count, vk::CompactMethod::prefix_scan));
    flags.write(words.data(), n * 4);
    vk::PatchBuffers vb;
    vb.flags = flags.range();
    vb.first = first;
    vb.count = count;
    vk::DrawListRanges vout;
    vout.list = list.range();
    vout.list_first = list_first;
    vout.command = command.range();
    vout.draw_count = draw_count.range();
    vout.scratch = scratch.range();
    vout.patches_per_command = k;
    vk::CompactPass vk_pass(vk().passes());
    vk().submit([&](VkCommandBuffer cmd) {
        vk_pass.run(cmd, vb, shared::kDrawMaskUnculled, shared::kDrawValueUnculled, vout,
                    vk::CompactMethod::prefix_scan);
    });
    EXPECT_EQ(list.read<std::uint32_t>(list_first + count), gl_list);
    EXPECT_EQ(command.read<std::uint32_t>(commands * 4), gl_commands);
    EXPECT_EQ(draw_count.read<std::uint32_t>(1)[0], gl_count);
    EXPECT_GT(gl_count, 1u);
}

TEST_F(VkGlEquality, HiZOcclusionAndFusedEqualGl) {
    const int w = 96, h = 64;
    for (const ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::reversed_infinite}) {
        RandomCase c = random_case(71, 1500, depth, false);
        c.patches.reserve(c.patches.size() + 200);
        for (int i = 0; i < 200; ++i) {
            const int column = i % 20, row = i / 20;  // a 20 x 10 grid of flat patches
            c.patches.push_back(test_patches::flat_patch(static_cast<float>(column) - 10.0f,
                                                         static_cast<float>(row) - 5.0f, 0.5f, i % 2 == 0));
        }
        const Mat4 m = c.camera.view_projection();
        const Vec3 eye = c.camera.eye;
        const std::vector<float> depths = wall_depths(c, m, depth, w, h);
        const std::uint32_t all = kCullFrustum | kCullBackPatch | kCullOcclusion;
        // GL: the depth texture, the pyramid, the occlusion pass and the fused pass.
        gl::PassContext& passes = gl_passes();
        GLuint depth_texture = 0;
        glCreateTextures(GL_TEXTURE_2D, 1, &depth_texture);
        glTextureStorage2D(depth_texture, 1, GL_DEPTH_COMPONENT32F, w, h);
        glTextureSubImage2D(depth_texture, 0, 0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, depths.data());
        gl::HiZTexture gl_hiz = gl::create_hiz_texture(w, h);
        gl::HiZBuildPass(passes).run(depth_texture, gl_hiz, depth);
        const std::vector<float> gl_pyramid = gl::read_hiz_texture(gl_hiz);
        std::vector<std::uint32_t> gl_occlusion, gl_fused;
        gl_occlusion =
            gl_words(c, [&](const gl::PatchBuffers& b) { gl::OcclusionPass(passes).run(b, m, depth, gl_hiz); });
        gl_fused = gl_words(c, [&](const gl::PatchBuffers& b) {
            gl::FusedCullPass(passes).run(b, all, m, depth, BackpatchMethod::tcone, eye, &gl_hiz);
        });
        glDeleteTextures(1, &depth_texture);
        glDeleteTextures(1, &gl_hiz.texture);
        // Vulkan.
        CaseBuffers occlusion_buffers(c), fused_buffers(c);
        vk::CullStatusPass status(vk().passes());
        vk::OcclusionPass occlusion(vk().passes());
        vk::FusedCullPass fused(vk().passes());
        bool reversed = false;
        const std::vector<float> vk_pyramid_texels =
            vk_pyramid(vk(), depths, w, h, depth, &reversed, [&](VkCommandBuffer cmd, const vk::HiZImage& hiz) {
                status.begin(cmd, occlusion_buffers.patch_buffers());
                occlusion.run(cmd, occlusion_buffers.patch_buffers(), m, depth, hiz);
                status.begin(cmd, fused_buffers.patch_buffers());
                fused.run(cmd, fused_buffers.patch_buffers(), all, m, depth, BackpatchMethod::tcone, eye, hiz);
            });
        ASSERT_EQ(vk_pyramid_texels.size(), gl_pyramid.size());
        EXPECT_EQ(std::memcmp(vk_pyramid_texels.data(), gl_pyramid.data(), gl_pyramid.size() * 4), 0)
            << clip_depth_name(depth);
        EXPECT_EQ(occlusion_buffers.flags.read<std::uint32_t>(c.patches.size()), gl_occlusion)
            << clip_depth_name(depth);
        EXPECT_EQ(fused_buffers.flags.read<std::uint32_t>(c.patches.size()), gl_fused) << clip_depth_name(depth);
        const std::size_t occluded =
            static_cast<std::size_t>(std::count(gl_fused.begin(), gl_fused.end(), kCullOcclusion));
        const std::size_t back = static_cast<std::size_t>(std::count(gl_fused.begin(), gl_fused.end(), kCullBackPatch));
        EXPECT_GT(occluded, 50u) << clip_depth_name(depth);
        EXPECT_GT(back, 20u) << clip_depth_name(depth);
    }
}

TEST_F(VkGlEquality, TwoFramesOfTheChainLeaveTheSameWordsAndCounts) {
    // Two frames of begin -> frustum -> tcone -> Hi-Z occlusion (no frustum) -> end on one flag
    // buffer, the second from a moved camera: statuses carry over, and every word and counter
    // equals GL's after each frame.
    const int w = 96, h = 64;
    const ClipDepth depth = ClipDepth::reversed;
    RandomCase c = random_case(91, 1500, depth, true);
    c.patches.reserve(c.patches.size() + 200);
    for (int i = 0; i < 200; ++i) {
        const int column = i % 20, row = i / 20;  // a 20 x 10 grid of flat patches
        c.patches.push_back(test_patches::flat_patch(static_cast<float>(column) - 10.0f, static_cast<float>(row) - 5.0f,
                                                     0.5f, i % 2 == 0));
    }
    c.margins.resize(c.patches.size(), 0.0f);
    Camera cameras[2] = {c.camera, c.camera};
    cameras[1].eye = cameras[1].eye + Vec3{0.3f, -0.2f, 0.1f};
    const std::vector<float> depths = wall_depths(c, cameras[0].view_projection(), depth, w, h);
    const std::size_t n = c.patches.size();
    // GL.
    gl::PassContext& passes = gl_passes();
    GLuint depth_texture = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &depth_texture);
    glTextureStorage2D(depth_texture, 1, GL_DEPTH_COMPONENT32F, w, h);
    glTextureSubImage2D(depth_texture, 0, 0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, depths.data());
    gl::HiZTexture gl_hiz = gl::create_hiz_texture(w, h);
    gl::HiZBuildPass(passes).run(depth_texture, gl_hiz, depth);
    gl::PatchBuffers gb;
    gb.control_points = gl_buffer(n * sizeof(BezierPatch), c.patches.data());
    gb.flags = gl_buffer(n * 4, nullptr);
    gb.margins = gl_buffer(n * 4, c.margins.data());
    gb.count = n;
    std::vector<std::uint32_t> gl_frame_words[2], gl_frame_counters[2];
    for (int f = 0; f < 2; ++f) {
        const GLuint counters = gl_buffer(shared::kCounterCount * 4, nullptr);
        const Mat4 m = cameras[f].view_projection();
        gl::CullStatusPass(passes).begin(gb);
        gl::FrustumPass(passes).run(gb, make_frustum_planes(m, depth));
        gl::BackpatchConePass(passes).run(gb, BackpatchMethod::tcone, cameras[f].eye);
        gl::OcclusionPass(passes).run(gb, m, depth, gl_hiz, false);
        gl::CullStatusPass(passes).end(gb, counters);
        gl_frame_words[f] = gl_read<std::uint32_t>(gb.flags, n);
        gl_frame_counters[f] = gl_read<std::uint32_t>(counters, shared::kCounterCount);
        glDeleteBuffers(1, &counters);
    }
    const GLuint names[] = {gb.control_points, gb.flags, gb.margins};
    glDeleteBuffers(3, names);
    glDeleteTextures(1, &depth_texture);
    glDeleteTextures(1, &gl_hiz.texture);
    // Vulkan: both frames in one command buffer, each frame's words copied out after its end.
    CaseBuffers b(c);
    HostBuffer counters[2] = {HostBuffer(shared::kCounterCount * 4), HostBuffer(shared::kCounterCount * 4)};
    HostBuffer words[2] = {HostBuffer(n * 4), HostBuffer(n * 4)};
    vk::CullStatusPass status(vk().passes());
    vk::FrustumPass frustum(vk().passes());
    vk::BackpatchConePass cones(vk().passes());
    vk::OcclusionPass occlusion(vk().passes());
    bool reversed = false;
    vk_pyramid(vk(), depths, w, h, depth, &reversed, [&](VkCommandBuffer cmd, const vk::HiZImage& hiz) {
        for (int f = 0; f < 2; ++f) {
            const Mat4 m = cameras[f].view_projection();
            status.begin(cmd, b.patch_buffers());
            frustum.run(cmd, b.patch_buffers(), make_frustum_planes(m, depth));
            cones.run(cmd, b.patch_buffers(), BackpatchMethod::tcone, cameras[f].eye);
            occlusion.run(cmd, b.patch_buffers(), m, depth, hiz, false);
            status.end(cmd, b.patch_buffers(), counters[f].range());
            const VkBufferCopy copy{0, 0, n * 4};
            vkCmdCopyBuffer(cmd, b.flags.range().buffer, words[f].range().buffer, 1, &copy);
            VkMemoryBarrier barrier{};
            barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
            barrier.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
            barrier.dstAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
            vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                                 &barrier, 0, nullptr, 0, nullptr);
        }
    });
    for (int f = 0; f < 2; ++f) {
        EXPECT_EQ(words[f].read<std::uint32_t>(n), gl_frame_words[f]) << "frame " << f;
        EXPECT_EQ(counters[f].read<std::uint32_t>(shared::kCounterCount), gl_frame_counters[f]) << "frame " << f;
    }
    // Every reason and both statuses occur.
    const std::vector<std::uint32_t>& last = gl_frame_words[1];
    for (const std::uint32_t word :
         {kCullFrustum, kCullBackPatch, kCullOcclusion, kStatusVisible, kStatusVisible | kStatusNewlyVisible})
        EXPECT_GT(std::count(last.begin(), last.end(), word), 0) << "word " << word;
}

#endif  // PATCHCULL_VK_TEST_GL
