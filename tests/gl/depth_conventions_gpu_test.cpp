// The depth conventions engines use, on the GPU (clip_space.h, gl_passes.h):
// - HiZBuildPass reads every depth format engines render into (32F, 32F + stencil, 24, 24 +
//   stencil) in a forward and a reversed convention: float formats give HiZPyramid::build's texels
//   bit for bit, 24-bit ones keys at or beyond the far end of each stored integer (never nearer);
// - no pass culls a patch with a NaN or infinite coordinate (any component of any point);
// - `render --clip-depth C --verify` reports no false culls in every convention and every cull
//   mode and method, with the decisions of zero-to-one (the strict id-buffer test: the culled
//   frame's ids equal the unculled frame's); a repeated or unknown --clip-depth is a one-line error.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"
#include "gl_test_util.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/hiz.h"
#include "shared.h"

using namespace patchcull;
using namespace patchcull::gl;
using namespace patchcull::cli_test;

namespace {

using test_patches::flat_patch;

// A width x height depth texture of internal format `format`, filled with `depth` (row 0 = bottom)
// quantized as the format stores it.
GLuint depth_texture(GLenum format, int width, int height, const std::vector<float>& depth) {
    GLuint tex = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, format, width, height);
    const std::size_t n = depth.size();
    if (format == GL_DEPTH_COMPONENT32F || format == GL_DEPTH_COMPONENT24) {
        glTextureSubImage2D(tex, 0, 0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
    } else if (format == GL_DEPTH32F_STENCIL8) {
        std::vector<std::uint32_t> words(2 * n);  // FLOAT_32_UNSIGNED_INT_24_8_REV: float, then stencil
        for (std::size_t i = 0; i < n; ++i) {
            std::memcpy(&words[2 * i], &depth[i], 4);
            words[2 * i + 1] = 0x5Au;
        }
        glTextureSubImage2D(tex, 0, 0, 0, width, height, GL_DEPTH_STENCIL, GL_FLOAT_32_UNSIGNED_INT_24_8_REV,
                            words.data());
    } else {  // GL_DEPTH24_STENCIL8
        std::vector<std::uint32_t> words(n);
        for (std::size_t i = 0; i < n; ++i)
            words[i] = (static_cast<std::uint32_t>(std::lround(double(depth[i]) * 16777215.0)) << 8) | 0x5Au;
        glTextureSubImage2D(tex, 0, 0, 0, width, height, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, words.data());
    }
    return tex;
}

// The 24-bit integers a 24-bit texture holds (read back exactly).
std::vector<std::uint32_t> stored_unorm24(GLuint tex, GLenum format, int width, int height) {
    const std::size_t n = static_cast<std::size_t>(width) * height;
    std::vector<std::uint32_t> words(n), u(n);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    if (format == GL_DEPTH24_STENCIL8) {
        glGetTextureImage(tex, 0, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, static_cast<GLsizei>(4 * n), words.data());
        for (std::size_t i = 0; i < n; ++i) u[i] = words[i] >> 8;
    } else {
        glGetTextureImage(tex, 0, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, static_cast<GLsizei>(4 * n), words.data());
        for (std::size_t i = 0; i < n; ++i)
            u[i] = static_cast<std::uint32_t>(std::llround(double(words[i]) * 16777215.0 / 4294967295.0));
    }
    return u;
}

// Patch p's flag words after `run` on a fresh buffer of patches (each word starts at 0).
struct RawPatches {
    GLuint points = 0, flags = 0, margins = 0;
    std::size_t count = 0;
    RawPatches(const std::vector<BezierPatch>& patches, float margin) : count(patches.size()) {
        glCreateBuffers(1, &points);
        glNamedBufferData(points, static_cast<GLsizeiptr>(patches.size() * sizeof(BezierPatch)), patches.data(),
                          GL_STATIC_DRAW);
        const std::vector<std::uint32_t> zero(count, 0u);
        glCreateBuffers(1, &flags);
        glNamedBufferData(flags, static_cast<GLsizeiptr>(count * 4), zero.data(), GL_DYNAMIC_COPY);
        const std::vector<float> m(count, margin);
        glCreateBuffers(1, &margins);
        glNamedBufferData(margins, static_cast<GLsizeiptr>(count * 4), m.data(), GL_STATIC_DRAW);
    }
    ~RawPatches() {
        const GLuint b[] = {points, flags, margins};
        glDeleteBuffers(3, b);
    }
    PatchBuffers buffers(bool with_margins) const { return {points, flags, with_margins ? margins : 0u, 0, count}; }
    std::vector<std::uint32_t> words() const {
        std::vector<std::uint32_t> w(count);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(flags, 0, static_cast<GLsizeiptr>(count * 4), w.data());
        return w;
    }
};

void expect_only_base_culled(const std::string& name, const BezierPatch& base, float margin,
                             const std::function<void(const PatchBuffers&)>& pass, bool with_margins = false) {
    const RawPatches raw(test_patches::poisoned_copies(base), margin);
    pass(raw.buffers(with_margins));
    const std::vector<std::uint32_t> w = raw.words();
    EXPECT_NE(w[0] & shared::kCullReasonMask, 0u) << name << ": the finite base patch must be culled";
    for (std::size_t i = 1; i < w.size(); ++i) {
        const std::size_t j = i - 1;
        EXPECT_EQ(w[i] & shared::kCullReasonMask, 0u)
            << name << ": point " << j / 12 << " component " << j / 3 % 4 << " value "
            << (j % 3 == 0   ? "NaN"
                : j % 3 == 1 ? "+Inf"
                             : "-Inf");
    }
}

}  // namespace

TEST(DepthConventionsGpu, HiZBuildReadsEveryDepthFormatInEveryDirection) {
    test::context();
    HiZBuildPass build(test::passes());
    constexpr int W = 37, H = 23;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::vector<float> depth(W * H);
    for (float& d : depth) d = u01(rng) < 0.1f ? 1.0f : u01(rng) < 0.1f ? 0.0f : u01(rng);
    for (GLenum format : {GL_DEPTH_COMPONENT32F, GL_DEPTH32F_STENCIL8, GL_DEPTH_COMPONENT24, GL_DEPTH24_STENCIL8}) {
        const GLuint tex = depth_texture(format, W, H, depth);
        const bool unorm24 = format == GL_DEPTH_COMPONENT24 || format == GL_DEPTH24_STENCIL8;
        for (ClipDepth convention : {ClipDepth::zero_to_one, ClipDepth::reversed}) {
            HiZTexture hiz = create_hiz_texture(W, H);
            build.run(tex, hiz, convention);
            EXPECT_EQ(hiz.reversed, is_reversed(convention));
            const std::vector<float> gpu = read_hiz_texture(hiz);
            HiZPyramid cpu;
            if (unorm24) {
                const std::vector<std::uint32_t> u = stored_unorm24(tex, format, W, H);
                cpu.build_unorm24(u.data(), W, H, 0, convention);
                // Level 0: at or beyond the far end of every stored integer of the footprint, and at
                // most a few steps beyond.
                for (int ty = 0; ty < cpu.level(0).height; ++ty)
                    for (int tx = 0; tx < cpu.level(0).width; ++tx) {
                        long double far_end = -1e30L;
                        for (int y = 2 * ty; y < std::min(H, 2 * ty + 2); ++y)
                            for (int x = 2 * tx; x < std::min(W, 2 * tx + 2); ++x) {
                                const long double v = u[y * W + x];
                                far_end = std::max(far_end, is_reversed(convention) ? -(v - 0.5L) / 16777215.0L
                                                                                    : (v + 0.5L) / 16777215.0L);
                            }
                        const float g =
                            gpu[cpu.level(0).offset + static_cast<std::size_t>(ty) * cpu.level(0).width + tx];
                        EXPECT_GE(static_cast<long double>(g), far_end) << format << " texel " << tx << "," << ty;
                        EXPECT_LE(static_cast<long double>(g), far_end + 4.0L / 16777215.0L) << format;
                    }
            } else {
                cpu.build(depth.data(), W, H, convention);
                ASSERT_EQ(gpu.size(), cpu.size());
                for (std::size_t t = 0; t < gpu.size(); ++t)
                    ASSERT_EQ(gpu[t], cpu.data()[t])
                        << "format " << format << " " << clip_depth_name(convention) << " texel " << t;
            }
            glDeleteTextures(1, &hiz.texture);
        }
        glDeleteTextures(1, &tex);
    }
    // A colour texture is refused by name.
    GLuint colour = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &colour);
    glTextureStorage2D(colour, 1, GL_RGBA8, W, H);
    HiZTexture hiz = create_hiz_texture(W, H);
    EXPECT_THROW(build.run(colour, hiz, ClipDepth::zero_to_one), Error);
    glDeleteTextures(1, &colour);
    glDeleteTextures(1, &hiz.texture);
}

TEST(DepthConventionsGpu, NoPassCullsAPatchWithANonFiniteCoordinate) {
    test::context();
    PassContext& ctx = test::passes();
    FrustumPass frustum(ctx);
    FrustumDispPass frustum_disp(ctx);
    OcclusionPass occlusion(ctx);
    FusedCullPass fused(ctx);
    DisplacedPass displaced(ctx);
    BackpatchConePass cones(ctx);
    BackpatchPtpPass ptp(ctx);
    HiZBuildPass build(ctx);
    const Camera camera;  // eye (0, 0, 5) looking down -z
    const BezierPatch outside = flat_patch(30.0f, 0.0f, 0.0f, false);
    const BezierPatch behind_wall = flat_patch(-0.5f, -0.5f, -2.0f, false);
    const BezierPatch facing_away = flat_patch(-0.5f, 0.5f, 0.0f, true);
    for (ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::reversed_infinite}) {
        const Mat4 proj = perspective(camera.fovy_radians, camera.aspect, camera.z_near, camera.z_far, depth);
        const Mat4 m = proj * camera.view();
        const std::string tag = std::string(" (") + clip_depth_name(depth) + ")";
        const std::vector<float> wall(64 * 64, is_reversed(depth) ? 0.999f : 0.001f);
        const GLuint tex = depth_texture(GL_DEPTH_COMPONENT32F, 64, 64, wall);
        HiZTexture hiz = create_hiz_texture(64, 64);
        build.run(tex, hiz, depth);
        const FrustumPlanes planes = make_frustum_planes(m, depth);
        expect_only_base_culled("FrustumPass" + tag, outside, 0.0f,
                                [&](const PatchBuffers& b) { frustum.run(b, planes); });
        expect_only_base_culled(
            "FrustumPass margins" + tag, outside, 0.25f, [&](const PatchBuffers& b) { frustum.run(b, planes); }, true);
        expect_only_base_culled(
            "FrustumDispPass" + tag, outside, 0.25f, [&](const PatchBuffers& b) { frustum_disp.run(b, m, depth); },
            true);
        for (const BezierPatch* base : {&outside, &behind_wall}) {
            const std::string where = (base == &outside ? " outside" : " occluded") + tag;
            expect_only_base_culled("OcclusionPass" + where, *base, 0.0f,
                                    [&](const PatchBuffers& b) { occlusion.run(b, m, depth, hiz, true); });
            expect_only_base_culled("FusedCullPass" + where, *base, 0.0f, [&](const PatchBuffers& b) {
                fused.run(b, shared::kCullFrustum | shared::kCullBackPatch | shared::kCullOcclusion, m, depth,
                          BackpatchMethod::tcone, camera.eye, &hiz);
            });
            const DisplacedCullView view = make_displaced_cull_view(camera.view(), proj, depth);
            expect_only_base_culled("DisplacedPass" + where, *base, 0.0f, [&](const PatchBuffers& b) {
                displaced.run(b, 0, DisplacedBoundKind::caf, NormalConeKind::full, view, &hiz, false);
            });
        }
        glDeleteTextures(1, &hiz.texture);
        glDeleteTextures(1, &tex);
    }
    const float alpha = clip_space_eye_alpha(camera.projection());
    expect_only_base_culled("BackpatchConePass tcone", facing_away, 0.0f,
                            [&](const PatchBuffers& b) { cones.run(b, BackpatchMethod::tcone, camera.eye); });
    expect_only_base_culled("BackpatchConePass ncone", facing_away, 0.0f,
                            [&](const PatchBuffers& b) { cones.run(b, BackpatchMethod::ncone, camera.eye); });
    expect_only_base_culled("BackpatchPtpPass", facing_away, 0.0f,
                            [&](const PatchBuffers& b) { ptp.run(b, camera.view_projection(), alpha, PtpRule::ncnt); });
}

// The strict id-buffer test in every convention: the same scene and camera path drawn, culled and
// verified in each, for every cull mode, back-patch method, frustum test, the fused pass, GPU
// posing, the displaced bounds, `auto`, and every object-level occlusion method (city_small for
// the query methods and the horizon, two rooms for portals). In every convention the test named
// by the case culls something, nothing is culled falsely, and the frustum counts equal
// zero-to-one's and the occlusion counts are within 1% of them (the conventions round depth
// differently, so a patch at the edge of occlusion may go either way).
TEST(DepthConventionsGpu, RenderVerifiesEveryModeInEveryConvention) {
    enum class Culls { frustum, backpatch, occlusion, objects };
    const std::string rooms = std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/scenes/two_rooms.json";
    const std::string city = std::string(PATCHCULL_SOURCE_DIR) + "/data/scenes/city_small.json";
    // Each case and the counter that must be positive in every convention.
    const std::vector<std::pair<std::string, Culls>> cases = {
        {"default --frames 2 --cull frustum", Culls::frustum},
        {"default --frames 2 --cull frustum --frustum aabb", Culls::frustum},
        {"default --frames 2 --cull backpatch --backpatch tcone", Culls::backpatch},
        {"default --frames 2 --cull backpatch --backpatch ncone", Culls::backpatch},
        {"default --frames 2 --cull backpatch --backpatch ptp", Culls::backpatch},
        {"default --frames 2 --cull occlusion", Culls::occlusion},
        {"default --frames 2 --cull all", Culls::occlusion},
        {"default --frames 2 --cull all --fused-pass", Culls::occlusion},
        {"default --frames 2 --cull all --pose gpu --bound caf --cone acon", Culls::occlusion},
        {"default --frames 2 --cull auto", Culls::occlusion},
        {city + " --frames 1 --objects frustum --object-occlusion stop-and-wait", Culls::objects},
        {city + " --frames 1 --objects bvh --object-occlusion batched", Culls::objects},
        {city + " --frames 1 --objects bvh --object-occlusion chc", Culls::objects},
        {city + " --frames 1 --objects bvh+backface --object-occlusion chc++", Culls::objects},
        {city + " --frames 1 --objects bvh+backface --object-occlusion horizon", Culls::objects},
        {rooms + " --frames 2 --objects frustum --object-occlusion portals", Culls::objects},
    };
    for (const auto& [case_args, culls] : cases) {
        long reference_occluded = -1, reference_frustum = -1;
        for (const char* convention : {"zero-to-one", "minus-one-to-one", "reversed", "reversed-infinite"}) {
            const std::string args =
                "render " + case_args + " --size 64x48 --tess 2 --clip-depth " + convention + " --verify --json";
            const CliRun r = run(args);
            ASSERT_EQ(r.status, 0) << args << "\n" << r.err;
            const auto j = nlohmann::json::parse(r.out);
            EXPECT_EQ(j["clip_depth"], convention);
            EXPECT_EQ(j["false_culls"], 0) << args;
            EXPECT_EQ(j["verified"], true) << args;
            long occluded = 0, frustum = 0, backpatch = 0, objects = 0;
            for (const auto& f : j["frames"]) {
                occluded += f["occlusion_culled"].get<long>();
                frustum += f["frustum_culled"].get<long>();
                backpatch += f["backpatch_culled"].get<long>();
                if (f.contains("objects")) {
                    const auto& o = f["objects"]["occlusion"];
                    objects += o.value("occlusion_culled", 0L) + o.value("objects_culled", 0L);
                }
            }
            const long named[] = {frustum, backpatch, occluded, objects};
            EXPECT_GT(named[static_cast<int>(culls)], 0) << args;
            if (reference_occluded < 0) {
                reference_occluded = occluded;
                reference_frustum = frustum;
                continue;
            }
            EXPECT_EQ(frustum, reference_frustum) << args;
            EXPECT_NEAR(double(occluded), double(reference_occluded), 0.01 * double(reference_occluded) + 2) << args;
        }
    }
    expect_one_line_error(run("render default --frames 1 --clip-depth reverse"), "--clip-depth");
    expect_one_line_error(run("render default --frames 1 --clip-depth reversed --clip-depth reversed"), "--clip-depth");
}
