// FusedCullPass (gl_passes.h, shaders/fused_cull.comp.glsl) against the flag chain it replaces:
// on random batches (the split teapot and random bumpy sheets, a third rational, some displaced,
// some already culled by the object level) and random cameras, with a Hi-Z pyramid built from a
// real depth buffer (a random half of the patches drawn), the flag words after the fused pass equal
// those after FrustumPass -> BackpatchConePass -> OcclusionPass(with_frustum = false), word for
// word, for every subset of the tests, tcone and ncone, both clip-depth conventions; a sub-range
// leaves the words outside it alone; and without margins the reasons equal the CPU kernels'
// (cull_occlusion_scalar's frustum and Hi-Z decisions, cull_tcone/ncone_scalar's back-patch ones,
// taken in the chain's order, and the CPU fused kernel cull_fused_scalar with the plan frustum,
// back-patch, Hi-Z) on the same matrix and pyramid.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"
#include "shared.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

struct Passes {
    FrustumPass frustum{test::passes()};
    BackpatchConePass cones{test::passes()};
    OcclusionPass occlusion{test::passes()};
    FusedCullPass fused{test::passes()};
    HiZBuildPass hiz_build{test::passes()};
};

Passes& passes() {
    static Passes p;
    return p;
}

// One test setup: patches on the renderer, a camera, the pyramid of the drawn half.
struct TestView {
    Mat4 m;  // the camera's matrix in `depth`'s convention
    ClipDepth depth = ClipDepth::zero_to_one;
    Vec3 eye;
    HiZTexture hiz;
};

// The chain the fused pass replaces, from `words` (reasons and statuses as given).
std::vector<std::uint32_t> run_chain(PatchRenderer& r, const PatchBuffers& b, const std::vector<std::uint32_t>& words,
                                     std::uint32_t tests, BackpatchMethod method, const TestView& s) {
    r.set_flag_words(words);
    Passes& p = passes();
    const Mat4 m01 = to_zero_to_one(s.m, s.depth);
    if (tests & kCullFrustum) p.frustum.run(b, make_frustum_planes(m01, ClipDepth::zero_to_one));
    if (tests & kCullBackPatch) p.cones.run(b, method, s.eye);
    if (tests & kCullOcclusion) p.occlusion.run(b, s.m, s.depth, s.hiz, false);
    return r.read_cull_flags();
}

std::vector<std::uint32_t> run_fused(PatchRenderer& r, const PatchBuffers& b, const std::vector<std::uint32_t>& words,
                                     std::uint32_t tests, BackpatchMethod method, const TestView& s) {
    r.set_flag_words(words);
    passes().fused.run(b, tests, s.m, s.depth, method, s.eye, &s.hiz);
    return r.read_cull_flags();
}

std::size_t count_differences(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b,
                              const std::string& what) {
    std::size_t n = 0;
    for (std::size_t p = 0; p < a.size(); ++p)
        if (a[p] != b[p] && ++n <= 5)
            ADD_FAILURE() << what << ": patch " << p << " chain 0x" << std::hex << a[p] << " fused 0x" << b[p];
    return n;
}

// A bumpy sheet of side `size` at `centre`, random orientation, w = 1 or random (rational).
BezierPatch random_sheet(std::mt19937& rng, Vec3 centre, float size, bool rational) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const Vec3 a = normalize(Vec3{u(rng), u(rng), u(rng)});
    const Vec3 bdir = normalize(cross(a, Vec3{u(rng), u(rng), u(rng)}));
    const Vec3 n = cross(a, bdir);
    BezierPatch patch;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const Vec3 x =
                centre + a * (size * (i / 1.5f - 1)) + bdir * (size * (j / 1.5f - 1)) + n * (size * 0.3f * u(rng));
            patch.cp[4 * j + i] = homogeneous(x, rational ? std::pow(2.0f, 1.5f * u(rng)) : 1.0f);
        }
    return patch;
}

struct Totals {
    std::size_t frustum = 0, backpatch = 0, occlusion = 0, visible = 0;
};

}  // namespace

TEST(FusedCullPass, FlagWordsEqualTheChainForEveryTestSubset) {
    std::mt19937 rng(20261202);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    auto range = [&](float lo, float hi) { return lo + (hi - lo) * u01(rng); };
    PatchRenderer r(test::context());
    const int sizes[][2] = {{256, 256}, {203, 150}, {120, 250}, {320, 180}};
    const std::vector<BezierPatch> teapot = test::split_teapot(2);
    Totals total;
    for (int round = 0; round < 4; ++round) {
        // The teapot (closed enough for the cones to cull its far side) plus random sheets.
        Camera cam;
        cam.target = {range(-0.5f, 0.5f), range(-0.5f, 0.5f), range(0.5f, 2.0f)};
        cam.eye = cam.target + normalize(Vec3{range(-1, 1), range(-1, 1), range(-1, 1)}) * range(3.0f, 7.0f);
        cam.up = {0, 0, 1};
        cam.fovy_radians = range(0.5f, 1.4f);
        cam.z_near = range(0.05f, 0.3f);
        cam.z_far = cam.z_near + range(6.0f, 14.0f);
        const int w = sizes[round][0], h = sizes[round][1];
        cam.aspect = float(w) / float(h);
        const Vec3 forward = normalize(cam.target - cam.eye);
        std::vector<BezierPatch> patches = teapot;
        for (int p = 0; p < 700; ++p) {
            const float along = p % 10 == 0 ? range(-1.0f, 0.5f) : range(0.2f, 10.0f);
            const Vec3 centre = cam.eye + forward * along +
                                Vec3{range(-1, 1), range(-1, 1), range(-1, 1)} * (0.2f + 0.6f * std::fabs(along));
            patches.push_back(random_sheet(rng, centre, std::pow(10.0f, range(-2.0f, -0.3f)), p % 3 == 0));
        }
        // Rounds 0 and 2 with margins (a tenth displaced), 1 and 3 without a margin buffer.
        const bool with_margins = round % 2 == 0;
        std::vector<float> margins(patches.size(), 0.0f);
        for (float& d : margins)
            if (u01(rng) < 0.1f) d = range(0.001f, 0.1f);
        if (with_margins)
            r.set_patches(patches, test::margins_only(margins));
        else
            r.set_patches(patches);
        std::vector<std::uint8_t> culled(patches.size(), 0);
        for (auto& c : culled) c = u01(rng) < 0.5f;
        r.set_cull_flags(culled.data());
        RenderParams params;
        params.view = cam.view();
        params.projection = cam.projection();
        params.width = w;
        params.height = h;
        params.tess_level = 5;
        r.render(params);
        TestView s;
        s.eye = cam.eye;
        s.hiz = create_hiz_texture(w, h);
        passes().hiz_build.run(r.depth_texture(), s.hiz);
        // Start words: random statuses, a twentieth already culled by the object level.
        std::vector<std::uint32_t> words(patches.size());
        for (std::uint32_t& word : words) {
            const float x = u01(rng);
            word = x < 0.4f ? 0u : x < 0.8f ? kStatusVisible : kStatusVisible | kStatusNewlyVisible;
            if (u01(rng) < 0.05f) word |= kCullObject;
        }
        const PatchBuffers b = r.patch_buffers();
        for (ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one}) {
            s.depth = depth;
            s.m = perspective(cam.fovy_radians, cam.aspect, cam.z_near, cam.z_far, depth) * cam.view();
            for (BackpatchMethod method : {BackpatchMethod::tcone, BackpatchMethod::ncone}) {
                for (std::uint32_t tests = 1; tests <= 7; ++tests) {
                    // ncone's program is slow on llvmpipe: its own subsets only in the first convention.
                    if (method == BackpatchMethod::ncone &&
                        (!(tests & kCullBackPatch) || depth != ClipDepth::zero_to_one))
                        continue;
                    const std::string what = "round " + std::to_string(round) + " " +
                                             (depth == ClipDepth::zero_to_one ? "0..1" : "-1..1") + " " +
                                             backpatch_method_name(method) + " tests " + std::to_string(tests);
                    const std::vector<std::uint32_t> chain = run_chain(r, b, words, tests, method, s);
                    const std::vector<std::uint32_t> fused = run_fused(r, b, words, tests, method, s);
                    EXPECT_EQ(count_differences(chain, fused, what), 0u) << what;
                    if (tests == 7) {
                        for (std::uint32_t word : fused) {
                            const std::uint32_t reason = word & kCullReasonMask;
                            total.frustum += reason == kCullFrustum;
                            total.backpatch += reason == kCullBackPatch;
                            total.occlusion += reason == kCullOcclusion;
                            total.visible += reason == 0;
                        }
                    }
                }
            }
        }
        // A sub-range: the words outside it stay as they were.
        PatchBuffers part = b;
        part.first = 100;
        part.count = 700;
        s.depth = ClipDepth::zero_to_one;
        s.m = cam.view_projection();
        const std::vector<std::uint32_t> chain = run_chain(r, part, words, 7, BackpatchMethod::tcone, s);
        const std::vector<std::uint32_t> fused = run_fused(r, part, words, 7, BackpatchMethod::tcone, s);
        EXPECT_EQ(count_differences(chain, fused, "sub-range"), 0u);
        for (std::size_t p = 0; p < words.size(); ++p)
            if (p < 100 || p >= 800) {
                EXPECT_EQ(fused[p], words[p]) << "patch " << p << " outside the range";
            }
        glDeleteTextures(1, &s.hiz.texture);
    }
    // Every test decides something (counted over both conventions and both cones).
    EXPECT_GT(total.frustum, 300u);
    EXPECT_GT(total.backpatch, 300u);
    EXPECT_GT(total.occlusion, 100u);
    EXPECT_GT(total.visible, 300u);
}

TEST(FusedCullPass, ReasonsEqualTheCpuKernels) {
    // Without margins: frustum / occluded from cull_occlusion_scalar (which runs the frustum test
    // first), back-patch from cull_tcone_scalar / cull_ncone_scalar, taken in the chain's order.
    std::mt19937 rng(77);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    auto range = [&](float lo, float hi) { return lo + (hi - lo) * u01(rng); };
    PatchRenderer r(test::context());
    std::size_t decided[4] = {};
    for (int round = 0; round < 3; ++round) {
        const int w = round == 1 ? 211 : 256, h = round == 2 ? 97 : 192;
        Camera cam;
        cam.target = {range(-0.3f, 0.3f), range(-0.3f, 0.3f), range(0.8f, 1.5f)};
        cam.eye = cam.target + normalize(Vec3{range(-1, 1), range(-1, 1), range(-0.5f, 1)}) * range(3.0f, 6.0f);
        cam.up = {0, 0, 1};
        cam.z_near = 0.1f;
        cam.z_far = 20.0f;
        cam.aspect = float(w) / float(h);
        std::vector<BezierPatch> patches = test::split_teapot(2);
        const Vec3 forward = normalize(cam.target - cam.eye);
        for (int p = 0; p < 500; ++p)
            patches.push_back(random_sheet(
                rng, cam.eye + forward * range(0.3f, 9.0f) + Vec3{range(-2, 2), range(-2, 2), range(-2, 2)},
                std::pow(10.0f, range(-1.8f, -0.4f)), p % 4 == 0));
        r.set_patches(patches);
        std::vector<std::uint8_t> drawn(patches.size(), 0);
        for (auto& c : drawn) c = u01(rng) < 0.5f;
        r.set_cull_flags(drawn.data());
        RenderParams params;
        params.view = cam.view();
        params.projection = cam.projection();
        params.width = w;
        params.height = h;
        params.tess_level = 5;
        r.render(params);
        const std::vector<float> depth = r.read_depth_bottom_up();
        HiZPyramid cpu_hiz;
        cpu_hiz.build(depth.data(), w, h);
        TestView s;
        s.m = cam.view_projection();
        s.eye = cam.eye;
        s.hiz = create_hiz_texture(w, h);
        passes().hiz_build.run(r.depth_texture(), s.hiz);
        const PatchBatch batch = make_batch(patches);
        std::vector<std::uint8_t> hiz_out(patches.size()), cone_out(patches.size());
        cull_occlusion_scalar(batch.view(), s.m, ClipDepth::zero_to_one, cpu_hiz, hiz_out.data());
        for (BackpatchMethod method : {BackpatchMethod::tcone, BackpatchMethod::ncone}) {
            if (method == BackpatchMethod::tcone)
                cull_tcone_scalar(batch.view(), cam.eye, cone_out.data());
            else
                cull_ncone_scalar(batch.view(), cam.eye, cone_out.data());
            const std::vector<std::uint32_t> words =
                run_fused(r, r.patch_buffers(), std::vector<std::uint32_t>(patches.size(), 0u), 7, method, s);
            std::size_t mismatched = 0;
            // The CPU fused kernel, plan F, B, H (its default), on the same pyramid.
            std::vector<std::uint8_t> fused_cpu(patches.size(), 0xEE);
            const FusedCullSetup setup = make_fused_setup(
                s.m, ClipDepth::zero_to_one, cam.eye,
                method == BackpatchMethod::tcone ? BackPatchCone::tcone : BackPatchCone::ncone, &cpu_hiz);
            cull_fused_scalar(batch.view(), setup, FusedPlan{}, fused_cpu.data());
            for (std::size_t p = 0; p < patches.size(); ++p) {
                const std::uint8_t d = fused_cpu[p];
                const std::uint32_t cpu = d == kFusedFrustumCulled     ? kCullFrustum
                                          : d == kFusedBackPatchCulled ? kCullBackPatch
                                          : d == kFusedOccluded        ? kCullOcclusion
                                                                       : 0u;
                if ((words[p] & kCullReasonMask) != cpu && ++mismatched <= 5)
                    ADD_FAILURE() << "round " << round << " " << backpatch_method_name(method) << ": patch " << p
                                  << " GPU " << (words[p] & kCullReasonMask) << " cull_fused_scalar " << int(d);
            }
            for (std::size_t p = 0; p < patches.size(); ++p) {
                const std::uint32_t cpu = hiz_out[p] == kHiZFrustumCulled ? kCullFrustum
                                          : cone_out[p]                   ? kCullBackPatch
                                          : hiz_out[p] == kHiZOccluded    ? kCullOcclusion
                                                                          : 0u;
                const std::uint32_t gpu = words[p] & kCullReasonMask;
                if (gpu != cpu && ++mismatched <= 5)
                    ADD_FAILURE() << "round " << round << " " << backpatch_method_name(method) << ": patch " << p
                                  << " GPU " << gpu << " CPU " << cpu;
                decided[cpu == 0 ? 0 : cpu == kCullFrustum ? 1 : cpu == kCullBackPatch ? 2 : 3]++;
            }
            EXPECT_EQ(mismatched, 0u) << "round " << round << " " << backpatch_method_name(method);
        }
        glDeleteTextures(1, &s.hiz.texture);
    }
    for (std::size_t n : decided) EXPECT_GT(n, 50u);
}

TEST(FusedCullPass, RefusesPtpMissingPyramidsAndUnknownTests) {
    PatchRenderer r(test::context());
    r.set_patches(test::split_teapot(0));
    const Mat4 m;  // identity
    FusedCullPass& fused = passes().fused;
    EXPECT_THROW(
        fused.run(r.patch_buffers(), kCullBackPatch, m, ClipDepth::zero_to_one, BackpatchMethod::ptp, {}, nullptr),
        patchcull::Error);
    EXPECT_THROW(
        fused.run(r.patch_buffers(), kCullOcclusion, m, ClipDepth::zero_to_one, BackpatchMethod::tcone, {}, nullptr),
        patchcull::Error);
    EXPECT_THROW(
        fused.run(r.patch_buffers(), kCullObject, m, ClipDepth::zero_to_one, BackpatchMethod::tcone, {}, nullptr),
        patchcull::Error);
    // ptp is fine when the back-patch test is not asked for; no pyramid is needed without occlusion.
    EXPECT_NO_THROW(
        fused.run(r.patch_buffers(), kCullFrustum, m, ClipDepth::zero_to_one, BackpatchMethod::ptp, {}, nullptr));
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(FusedCullPass, KeepsTheStateContract) {
    // gl_passes.h: no program in use afterwards, its buffers and pyramid left bound where it bound
    // them, and a GL error left by the caller reported as the caller's.
    PatchRenderer r(test::context());
    r.set_patches(test::split_teapot(1));
    Camera cam;
    cam.eye = {0, -6, 2};
    cam.target = {0, 0, 1};
    cam.up = {0, 0, 1};
    RenderParams params;
    params.view = cam.view();
    params.projection = cam.projection();
    params.width = params.height = 64;
    params.tess_level = 2;
    r.render(params);
    HiZTexture hiz = create_hiz_texture(64, 64);
    passes().hiz_build.run(r.depth_texture(), hiz);
    const PatchBuffers b = r.patch_buffers();
    passes().fused.run(b, 7, cam.view_projection(), ClipDepth::zero_to_one, BackpatchMethod::tcone, cam.eye, &hiz);
    GLint program = -1, flags = -1, points = -1, texture = -1;
    glGetIntegerv(GL_CURRENT_PROGRAM, &program);
    glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, shared::kBindingCullFlags, &flags);
    glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, shared::kBindingControlPoints, &points);
    glActiveTexture(GL_TEXTURE0 + shared::kTextureUnitHiZ);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &texture);
    glActiveTexture(GL_TEXTURE0);
    EXPECT_EQ(program, 0);
    EXPECT_EQ(static_cast<GLuint>(flags), b.flags);
    EXPECT_EQ(static_cast<GLuint>(points), b.control_points);
    EXPECT_EQ(static_cast<GLuint>(texture), hiz.texture);
    glBindBuffer(GL_ARRAY_BUFFER, 0xFFFFFFu);  // not a buffer name: GL_INVALID_OPERATION
    try {
        passes().fused.run(b, 7, cam.view_projection(), ClipDepth::zero_to_one, BackpatchMethod::tcone, cam.eye, &hiz);
        ADD_FAILURE() << "no error";
    } catch (const patchcull::Error& e) {
        EXPECT_NE(std::string(e.what()).find("pending before FusedCullPass"), std::string::npos) << e.what();
    }
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    glDeleteTextures(1, &hiz.texture);
}
