// GPU back-patch culling (patchcull/gl/gl_backpatch.h) against the CPU scalar kernels
// (patchcull/core/backpatch.h): decisions must be equal on the same inputs, for tcone, ncone and ptp
// with both rules; ptp's 64 control plane values must be bit-identical. The one-sided check
// (the GPU never culls a patch the CPU keeps) is counted separately so that a failure says which
// direction broke. Also: the generated shaders/ptp_schedule.h equals src/core/ptp_schedule.h's
// schedule, the cone constants of shaders/backpatch_cones.h equal cones_internal.h's, and the
// shaders' fma / division / sqrt are correctly rounded.
//
// Regenerate shaders/ptp_schedule.h after a change of src/core/ptp_table.inc or ptp_schedule.h:
//   PATCHCULL_WRITE_PTP_GLSL=1 <build>/tests/patchcull_gl_tests --gtest_filter=BackpatchGpu.PtpScheduleHeader*
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/cone_test_patches.h"
#include "core/cones_internal.h"
#include "core/ptp_internal.h"
#include "core/ptp_schedule.h"
#include "gl/gl_test_util.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/teapot.h"
#include "patchcull/gl/gl_backpatch.h"

namespace patchcull::gl {
namespace {

namespace fs = std::filesystem;
using cone_test::D3;
using cone_test::PatchGen;

BackpatchCuller& culler() {
    static BackpatchCuller c(test::context());
    return c;
}

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// ---- shaders/ptp_schedule.h -----------------------------------------------------------------------

std::string hex32(std::uint32_t v) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%08Xu", v);
    return buf;
}

template <class T, class F>
void emit_array(std::ostringstream& o, const char* type, const char* name, std::size_t n, int per_line, F value) {
    o << "const " << type << " " << name << "[" << n << "] = " << type << "[" << n << "](";
    for (std::size_t i = 0; i < n; ++i) {
        if (i % per_line == 0) o << "\n    ";
        o << value(i);
        if (i + 1 < n) o << ((i + 1) % per_line == 0 ? "," : ", ");
    }
    o << ");\n";
}

std::string ptp_schedule_glsl() {
    using ptp_detail::kSchedule;
    std::ostringstream o;
    o << "// shaders/ptp_schedule.h (GLSL only): the ptp kernels' evaluation schedule, GENERATED from\n"
         "// src/core/ptp_schedule.h's kSchedule (itself built from src/core/ptp_table.inc) by\n"
         "// tests/gl/backpatch_gpu_test.cpp, which fails when this file differs: do not edit. Regenerate:\n"
         "//   PATCHCULL_WRITE_PTP_GLSL=1 <build>/tests/patchcull_gl_tests "
         "--gtest_filter=BackpatchGpu.PtpScheduleHeader*\n"
         "// Used by backpatch_ptp.comp.glsl; the meaning of each array is that of ptp_schedule.h's Schedule:\n"
         "// - kPtpPairs[q] = a | b << 8: the point pairs (a < b) whose 2x2 minors (of (a, b - a)) are shared;\n"
         "// - kPtpSteps[s] = pair | third << 8 and kPtpStepWeights[s] (float bits, the table weight with the\n"
         "//   permutation sign folded in): acc = fma(weight, cross4Z from the pair's minors and point third, acc);\n"
         "//   the steps of destination d are [kPtpDestFirst[d], kPtpDestFirst[d + 1]), in table order;\n"
         "// - kPtpCornerOfDest[d]: index into kPtpCorners (dest | a << 8 | b << 16 | c << 24) and\n"
         "//   kPtpCornerWeights, or -1: t[d] = weight * det[p_a, p_b - p_a, p_c - p_a];\n"
         "// - the rounding-error margin's constants (float bits): kPtpMarginC1, C2, C3, Underflow,\n"
         "//   kPtpMarginWeights[d] = W_d, kPtpMarginWeightTerms[d] = W_d (K_d + 12), and the edges'\n"
         "//   control points kPtpEdgePoints[4 e + i] (ptp_schedule.h's kEdgePoints).\n";
    o << "const uint kPtpPairCount = " << ptp_detail::kPairCount << "u;\n";
    emit_array<std::uint32_t>(o, "uint", "kPtpPairs", ptp_detail::kPairCount, 8, [&](std::size_t i) {
        return std::to_string(kSchedule.pairs[i].a | (kSchedule.pairs[i].b << 8)) + "u";
    });
    emit_array<std::uint32_t>(o, "uint", "kPtpSteps", ptp_detail::kStepCount, 8, [&](std::size_t i) {
        return std::to_string(kSchedule.steps[i].pair | (kSchedule.steps[i].third << 8)) + "u";
    });
    emit_array<std::uint32_t>(o, "uint", "kPtpStepWeights", ptp_detail::kStepCount, 6, [&](std::size_t i) {
        return hex32(std::bit_cast<std::uint32_t>(kSchedule.steps[i].weight));
    });
    emit_array<std::uint32_t>(o, "uint", "kPtpDestFirst", 65, 13,
                              [&](std::size_t i) { return std::to_string(kSchedule.dest_first[i]) + "u"; });
    emit_array<int>(o, "int", "kPtpCornerOfDest", 64, 16,
                    [&](std::size_t i) { return std::to_string(int(kSchedule.corner_of_dest[i])); });
    emit_array<std::uint32_t>(o, "uint", "kPtpCorners", 4, 4, [&](std::size_t i) {
        const ptp_detail::Corner& c = kSchedule.corners[i];
        return hex32(c.dest | (c.a << 8) | (c.b << 16) | (std::uint32_t(c.c) << 24));
    });
    emit_array<std::uint32_t>(o, "uint", "kPtpCornerWeights", 4, 4, [&](std::size_t i) {
        return hex32(std::bit_cast<std::uint32_t>(kSchedule.corners[i].weight));
    });
    o << "const uint kPtpMarginC1 = " << hex32(std::bit_cast<std::uint32_t>(ptp_detail::kMarginC1)) << ";\n";
    o << "const uint kPtpMarginC2 = " << hex32(std::bit_cast<std::uint32_t>(ptp_detail::kMarginC2)) << ";\n";
    o << "const uint kPtpMarginC3 = " << hex32(std::bit_cast<std::uint32_t>(ptp_detail::kMarginC3)) << ";\n";
    o << "const uint kPtpMarginUnderflow = " << hex32(std::bit_cast<std::uint32_t>(ptp_detail::kMarginUnderflow))
      << ";\n";
    emit_array<std::uint32_t>(o, "uint", "kPtpMarginWeights", 64, 6, [&](std::size_t i) {
        return hex32(std::bit_cast<std::uint32_t>(ptp_detail::kMarginWeights.weight[i]));
    });
    emit_array<std::uint32_t>(o, "uint", "kPtpMarginWeightTerms", 64, 6, [&](std::size_t i) {
        return hex32(std::bit_cast<std::uint32_t>(ptp_detail::kMarginWeights.weight_terms[i]));
    });
    emit_array<std::uint32_t>(o, "uint", "kPtpEdgePoints", 16, 16, [&](std::size_t i) {
        return std::to_string(ptp_detail::kEdgePoints[i / 4][i % 4]) + "u";
    });
    return o.str();
}

TEST(BackpatchGpu, PtpScheduleHeaderMatchesCore) {
    const fs::path path = fs::path(PATCHCULL_SOURCE_DIR) / "shaders/ptp_schedule.h";
    const std::string expected = ptp_schedule_glsl();
    if (std::getenv("PATCHCULL_WRITE_PTP_GLSL")) {
        std::ofstream(path, std::ios::binary) << expected;
        GTEST_SKIP() << "wrote " << path;
    }
    EXPECT_EQ(read_text(path), expected) << path << " is stale: regenerate it (see the top of this file)";
}

TEST(BackpatchGpu, ConeConstantsMatchCore) {
    const std::string text = read_text(fs::path(PATCHCULL_SOURCE_DIR) / "shaders/backpatch_cones.h");
    namespace cd = cones_detail;
    const std::pair<const char*, float> constants[] = {{"kMinLen2", cd::kMinLen2},
                                                       {"kMaxLen2", cd::kMaxLen2},
                                                       {"kCosSlack", cd::kCosSlack},
                                                       {"kSinSlack", cd::kSinSlack},
                                                       {"kNormalRoundoff", cd::kNormalRoundoff},
                                                       {"kRadiusScale", cd::kRadiusScale},
                                                       {"kFacingSlack", cd::kFacingSlack}};
    for (const auto& [name, value] : constants) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "#define %s uintBitsToFloat(0x%08Xu)", name,
                      std::bit_cast<std::uint32_t>(value));
        EXPECT_NE(text.find(buf), std::string::npos) << "shaders/backpatch_cones.h lacks `" << buf << "`";
    }
}

// ---- exact arithmetic -----------------------------------------------------------------------------

float random_float(std::mt19937& rng, int min_exp, int max_exp) {
    std::uniform_int_distribution<std::uint32_t> mant(0, (1u << 23) - 1);
    std::uniform_int_distribution<int> ex(min_exp, max_exp), sign(0, 1);
    const float m = 1.0f + std::ldexp(static_cast<float>(mant(rng)), -23);
    return (sign(rng) ? -1.0f : 1.0f) * std::ldexp(m, ex(rng));
}

TEST(BackpatchGpu, FmaDivisionAndSqrtAreCorrectlyRounded) {
    std::mt19937 rng(7);
    std::vector<Vec3> in;
    for (int i = 0; i < 20000; ++i) {
        const float a = random_float(rng, -20, 20), b = random_float(rng, -20, 20);
        // c near -a*b half the time (cancellation), else random.
        const float c =
            i % 2 ? -(a * b) * (1.0f + std::ldexp(random_float(rng, -1, 0), -20)) : random_float(rng, -40, 40);
        in.push_back({a, b, c});
    }
    // Near-midpoint cases (the renderer's fma check) and quotients / roots of nearby values.
    for (int k = 0; k < 200; ++k) {
        const float a = std::ldexp(1.0f + std::ldexp(float(k), -23), -24), b = 1.0f - std::ldexp(1.0f, -23);
        in.push_back({a, b, 1.0f + std::ldexp(float(k + 1), -23)});
        in.push_back({1.0f + std::ldexp(float(k), -23), 1.0f - std::ldexp(float(k + 1), -24), 0.0f});
    }
    BackpatchCuller& c = culler();
    const std::vector<float> fma = c.probe(BackpatchProbe::fma, in);
    std::vector<Vec3> div_in = in, sqrt_in = in;
    for (Vec3& v : sqrt_in) v.x = std::fabs(v.x);
    const std::vector<float> div = c.probe(BackpatchProbe::div, div_in);
    const std::vector<float> sq = c.probe(BackpatchProbe::sqrt, sqrt_in);
    int bad_fma = 0, bad_div = 0, bad_sqrt = 0;
    for (std::size_t i = 0; i < in.size(); ++i) {
        const float ef = std::fma(in[i].x, in[i].y, in[i].z);
        // Subnormal results are flushed on llvmpipe (documented): skip them.
        if (std::fabs(ef) >= 0x1p-126f || ef == 0.0f)
            bad_fma += std::bit_cast<std::uint32_t>(fma[i]) != std::bit_cast<std::uint32_t>(ef);
        bad_div += std::bit_cast<std::uint32_t>(div[i]) != std::bit_cast<std::uint32_t>(div_in[i].x / div_in[i].y);
        bad_sqrt += std::bit_cast<std::uint32_t>(sq[i]) != std::bit_cast<std::uint32_t>(std::sqrt(sqrt_in[i].x));
    }
    // The correction steps alone, from guesses up to 3 ulps off (the driver's / and sqrt are exact
    // on llvmpipe, so pc_div and pc_sqrt above never needed them).
    std::vector<Vec3> div_guess, sqrt_guess;
    std::vector<float> div_want, sqrt_want;
    for (std::size_t i = 0; i < in.size(); i += 7)
        for (int off = -3; off <= 3; ++off) {
            const float q = div_in[i].x / div_in[i].y, s = std::sqrt(sqrt_in[i].x);
            auto shift = [off](float x) {  // off ulps away in magnitude
                return std::bit_cast<float>(static_cast<std::uint32_t>(std::bit_cast<std::uint32_t>(x) + off));
            };
            div_guess.push_back({div_in[i].x, div_in[i].y, shift(q)});
            div_want.push_back(q);
            sqrt_guess.push_back({sqrt_in[i].x, shift(s), 0.0f});
            sqrt_want.push_back(s);
        }
    const std::vector<float> div_fixed = c.probe(BackpatchProbe::div_from, div_guess);
    const std::vector<float> sqrt_fixed = c.probe(BackpatchProbe::sqrt_from, sqrt_guess);
    int bad_div_from = 0, bad_sqrt_from = 0;
    for (std::size_t i = 0; i < div_guess.size(); ++i) {
        bad_div_from += std::bit_cast<std::uint32_t>(div_fixed[i]) != std::bit_cast<std::uint32_t>(div_want[i]);
        bad_sqrt_from += std::bit_cast<std::uint32_t>(sqrt_fixed[i]) != std::bit_cast<std::uint32_t>(sqrt_want[i]);
    }
    EXPECT_EQ(bad_div_from, 0) << "of " << div_guess.size();
    EXPECT_EQ(bad_sqrt_from, 0) << "of " << sqrt_guess.size();
    EXPECT_EQ(bad_fma, 0) << "of " << in.size() << " (fma_via_double = " << c.fma_via_double() << ")";
    EXPECT_EQ(bad_div, 0) << "of " << in.size() << " (native_div_sqrt = " << test::passes().native_div_sqrt() << ")";
    EXPECT_EQ(bad_sqrt, 0) << "of " << in.size();
}

TEST(BackpatchGpu, SoftwareRasterizerDividesNatively) {
    // On llvmpipe the start-up check finds / and sqrt correctly rounded (LLVM's fdiv and sqrt), so
    // the shaders use them as they are; FmaDivisionAndSqrtAreCorrectlyRounded above then checks
    // those against the CPU, and the correction steps alone through the *_from modes.
    PassContext& passes = test::passes();
    if (!passes.is_software()) GTEST_SKIP() << "a GPU: the shaders correct its division";
    EXPECT_TRUE(passes.native_div_sqrt());
}

// ---- inputs ---------------------------------------------------------------------------------------

BezierPatch make_rational(BezierPatch p, std::mt19937& rng) {
    std::uniform_real_distribution<float> w(0.5f, 2.0f);
    for (Vec4& c : p.cp) {
        const float k = w(rng);
        c = {c.x * k, c.y * k, c.z * k, k};
    }
    return p;
}

// ~3000 patches: the teapot split twice (512, with its collapsed edges), the 32 originals, random
// sheets / clouds / collapsed edges at many scales (PatchGen::any), sheets passing close to the
// origin (so that an eye at the origin is close to them), and rational patches.
std::vector<BezierPatch> test_patches() {
    std::vector<BezierPatch> patches = test::split_teapot(2);
    for (const BezierPatch& p : teapot_patches()) patches.push_back(p);
    PatchGen gen(1234);
    std::mt19937 rng(99);
    for (int i = 0; i < 1700; ++i) patches.push_back(gen.any());
    for (int i = 0; i < 500; ++i) {
        const double size = std::pow(10.0, gen.uniform(-1, 1));
        const D3 centre = gen.unit() * (size * gen.uniform(0.01, 1.5));
        patches.push_back(gen.sheet(std::pow(10.0, gen.uniform(-3, -0.5)), size, centre));
    }
    for (int i = 0; i < 300; ++i) {
        BezierPatch p = i % 3 ? gen.any() : gen.sheet(0.05, 1.0, gen.unit() * gen.uniform(0, 3));
        patches.push_back(make_rational(p, rng));
    }
    return patches;
}

std::vector<Vec3> test_eyes() {
    std::vector<Vec3> eyes = {{0, 0, 0}, {0.01f, -0.02f, 0.015f}};
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1, 1);
    for (float r : {0.5f, 3.0f, 40.0f, 1000.0f}) eyes.push_back(Vec3{u(rng), u(rng), u(rng)} * r);
    return eyes;
}

struct Comparison {
    std::size_t total = 0, cpu_culled = 0, gpu_culled = 0, gpu_only = 0, cpu_only = 0;
};

Comparison compare(const std::vector<std::uint8_t>& cpu, const std::vector<std::uint8_t>& gpu) {
    Comparison c;
    c.total = cpu.size();
    for (std::size_t i = 0; i < cpu.size(); ++i) {
        c.cpu_culled += cpu[i] != 0;
        c.gpu_culled += gpu[i] != 0;
        c.gpu_only += gpu[i] && !cpu[i];
        c.cpu_only += cpu[i] && !gpu[i];
    }
    return c;
}

void check_cones(BackpatchMethod method) {
    const std::vector<BezierPatch> patches = test_patches();
    const PatchBatch batch = make_batch(patches);
    BackpatchCuller& c = culler();
    c.set_patches(batch.view());
    Comparison all;
    const bool tcone = method == BackpatchMethod::tcone;
    bool first_eye = true;
    for (const Vec3 eye : test_eyes()) {
        std::vector<std::uint8_t> cpu(patches.size()), gpu;
        if (tcone)
            cull_tcone_scalar(batch.view(), eye, cpu.data());
        else
            cull_ncone_scalar(batch.view(), eye, cpu.data());
        if (first_eye) {
            // The cones and spheres themselves, bit for bit (valid cones; invalid ones only as invalid).
            std::vector<float> cones;
            if (tcone)
                c.cull_tcone(eye, &gpu, &cones);
            else
                c.cull_ncone(eye, &gpu, &cones);
            ASSERT_EQ(cones.size(), patches.size() * 12);
            std::size_t valid = 0, bad = 0;
            auto same = [](float a, float b) {
                return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
            };
            for (std::size_t p = 0; p < patches.size(); ++p) {
                const NormalCone cone = tcone ? cones_detail::tangent_cone_polynomial(patches[p])
                                              : cones_detail::normal_cone_polynomial(patches[p]);
                const PatchSphere sphere = cones_detail::sphere_of_points<false>(patches[p]);
                const float* g = &cones[12 * p];
                bool ok = (g[5] != 0.0f) == cone.valid && same(g[6], sphere.center.x) && same(g[7], sphere.center.y) &&
                          same(g[8], sphere.center.z) && same(g[9], sphere.radius);
                if (cone.valid) {
                    ++valid;
                    ok = ok && same(g[0], cone.axis.x) && same(g[1], cone.axis.y) && same(g[2], cone.axis.z) &&
                         same(g[3], cone.cos_angle) && same(g[4], cone.sin_angle);
                }
                if (!ok && bad++ < 5)
                    ADD_FAILURE() << backpatch_method_name(method) << " patch " << p
                                  << ": GPU cone/sphere differs: valid " << g[5] << " vs " << cone.valid << ", cos "
                                  << g[3] << " vs " << cone.cos_angle << ", sin " << g[4] << " vs " << cone.sin_angle
                                  << ", radius " << g[9] << " vs " << sphere.radius;
            }
            std::printf("[ %s ] cones: %zu valid of %zu, %zu differ from the CPU's (bitwise)\n",
                        backpatch_method_name(method), valid, patches.size(), bad);
            EXPECT_EQ(bad, 0u);
            EXPECT_GT(valid, patches.size() / 2);
            first_eye = false;
        } else {
            c.cull(method, Mat4{}, eye, 0.0f, PtpRule::ncnt, &gpu);
        }
        ASSERT_EQ(gpu.size(), patches.size());
        const Comparison r = compare(cpu, gpu);
        EXPECT_EQ(r.gpu_only, 0u) << backpatch_method_name(method) << ": GPU culls patches the CPU keeps, eye " << eye.x
                                  << " " << eye.y << " " << eye.z;
        EXPECT_EQ(r.cpu_only, 0u) << backpatch_method_name(method) << ": CPU culls patches the GPU keeps, eye " << eye.x
                                  << " " << eye.y << " " << eye.z;
        all.total += r.total, all.cpu_culled += r.cpu_culled, all.gpu_culled += r.gpu_culled;
        all.gpu_only += r.gpu_only, all.cpu_only += r.cpu_only;
    }
    std::printf("[ %s ] %zu decisions, CPU culled %zu, GPU culled %zu, GPU-only %zu, CPU-only %zu\n",
                backpatch_method_name(method), all.total, all.cpu_culled, all.gpu_culled, all.gpu_only, all.cpu_only);
    // The comparison has teeth: a fair share is culled.
    EXPECT_GT(all.cpu_culled, all.total / 10);
    // The flag buffer holds kCullBackPatch / 0 (the cull_occlusion hook's layout).
    const std::vector<std::uint32_t> words = c.read_flag_words();
    ASSERT_EQ(words.size(), patches.size());
    for (std::uint32_t w : words) ASSERT_TRUE(w == 0 || w == kCullBackPatch) << w;
}

TEST(BackpatchGpu, TconeDecisionsEqualCpu) { check_cones(BackpatchMethod::tcone); }
TEST(BackpatchGpu, NconeDecisionsEqualCpu) { check_cones(BackpatchMethod::ncone); }

// ---- ptp --------------------------------------------------------------------------------------------

struct View {
    Mat4 object_to_clip;
    float alpha;
};

View make_view(Vec3 eye, Vec3 target, const Mat4& model = Mat4{}) {
    const Mat4 proj = perspective(1.0471975512f, 1.5f, 0.05f, 500.0f);
    Vec3 up{0, 1, 0};
    const Vec3 f = target - eye;
    if (std::fabs(f.x) < 1e-3f && std::fabs(f.z) < 1e-3f) up = {1, 0, 0};
    return {proj * look_at(eye, target, up) * model, clip_space_eye_alpha(proj)};
}

Mat4 mirror_x() {
    Mat4 m;
    m.at(0, 0) = -1;
    return m;
}

TEST(BackpatchGpu, PtpDecisionsAndPlanesEqualCpu) {
    const std::vector<BezierPatch> patches = test_patches();
    const PatchBatch batch = make_batch(patches);
    BackpatchCuller& c = culler();
    c.set_patches(batch.view());
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1, 1);
    std::vector<View> views = {make_view({0.02f, 0.01f, -0.03f}, {1, 0, 0}), make_view({3, 2, 1}, {0, 0, 0}),
                               make_view({-40, 10, 25}, {0, 0, 0}), make_view({0, 0, 6}, {0, 0, 0}, mirror_x()),
                               make_view({5, -7, 3}, {0, 0, 1.5f}, mirror_x())};
    for (int i = 0; i < 2; ++i) views.push_back(make_view(Vec3{u(rng), u(rng), u(rng)} * 12.0f, {0, 0, 0}));
    Comparison all;
    std::size_t plane_mismatch = 0, planes_total = 0;
    for (std::size_t v = 0; v < views.size(); ++v) {
        const View& view = views[v];
        ptp_detail::PtpClipRows rows;
        ASSERT_TRUE(ptp_detail::ptp_clip_rows(view.object_to_clip, view.alpha, rows));
        for (const PtpRule rule : {PtpRule::ncnt, PtpRule::pcnt}) {
            std::vector<std::uint8_t> cpu(patches.size()), gpu;
            std::vector<float> planes, margins;
            cull_ptp_scalar(batch.view(), view.object_to_clip, view.alpha, rule, cpu.data());
            const bool diagnostics = rule == PtpRule::ncnt;
            c.cull_ptp(view.object_to_clip, view.alpha, rule, &gpu, diagnostics ? &planes : nullptr,
                       diagnostics ? &margins : nullptr);
            ASSERT_EQ(gpu.size(), patches.size());
            const Comparison r = compare(cpu, gpu);
            const char* rn = rule == PtpRule::ncnt ? "ncnt" : "pcnt";
            EXPECT_EQ(r.gpu_only, 0u) << "ptp-" << rn << " view " << v << ": GPU culls patches the CPU keeps";
            EXPECT_EQ(r.cpu_only, 0u) << "ptp-" << rn << " view " << v << ": CPU culls patches the GPU keeps";
            all.total += r.total, all.cpu_culled += r.cpu_culled, all.gpu_culled += r.gpu_culled;
            all.gpu_only += r.gpu_only, all.cpu_only += r.cpu_only;
            if (rule != PtpRule::ncnt) continue;
            ASSERT_EQ(planes.size(), patches.size() * 64);
            ASSERT_EQ(margins.size(), patches.size() * 64);
            for (std::size_t p = 0; p < patches.size(); ++p) {
                float t[64], thr[64];
                ptp_detail::ptp_control_planes_z(patches[p], rows, t);
                ASSERT_TRUE(ptp_detail::ptp_rounding_margins(patches[p], rows, thr));
                for (int d = 0; d < 64; ++d) {
                    planes_total += 2;
                    const bool t_equal =
                        std::bit_cast<std::uint32_t>(t[d]) == std::bit_cast<std::uint32_t>(planes[64 * p + d]);
                    const bool thr_equal =
                        std::bit_cast<std::uint32_t>(thr[d]) == std::bit_cast<std::uint32_t>(margins[64 * p + d]);
                    if (!t_equal || !thr_equal) {
                        if (plane_mismatch < 5)
                            ADD_FAILURE()
                                << "view " << v << " patch " << p << " d " << d << ": CPU t " << t[d] << " thr "
                                << thr[d] << ", GPU t " << planes[64 * p + d] << " thr " << margins[64 * p + d];
                        plane_mismatch += !t_equal + !thr_equal;
                    }
                }
            }
        }
    }
    std::printf(
        "[ ptp ] %zu decisions, CPU culled %zu, GPU culled %zu, GPU-only %zu, CPU-only %zu; planes and margins %zu of "
        "%zu differ\n",
        all.total, all.cpu_culled, all.gpu_culled, all.gpu_only, all.cpu_only, plane_mismatch, planes_total);
    EXPECT_EQ(plane_mismatch, 0u);
    EXPECT_GT(all.cpu_culled, all.total / 10);
}

TEST(BackpatchGpu, PtpCullsNothingForDegenerateViewsAndSmallSets) {
    BackpatchCuller& c = culler();
    const std::vector<BezierPatch> teapot = teapot_patches();
    c.set_patches(teapot);
    const View view = make_view({0, 0, 8}, {0, 0, 0});
    std::vector<std::uint8_t> gpu, cpu(teapot.size());
    // alpha = 0 and a singular matrix: nothing culled (as the CPU).
    c.cull_ptp(view.object_to_clip, 0.0f, PtpRule::pcnt, &gpu);
    EXPECT_EQ(std::count(gpu.begin(), gpu.end(), 1), 0);
    Mat4 singular = view.object_to_clip;
    for (int col = 0; col < 4; ++col) singular.at(3, col) = singular.at(0, col);
    c.cull_ptp(singular, view.alpha, PtpRule::pcnt, &gpu);
    EXPECT_EQ(std::count(gpu.begin(), gpu.end(), 1), 0);
    // From above, the teapot's lid top (collapsed edges) is pcnt-culled on both sides equally.
    const PatchBatch batch = make_batch(teapot);
    const View below = make_view({0.3f, 0.2f, -8}, {0, 0, 0});
    for (const PtpRule rule : {PtpRule::ncnt, PtpRule::pcnt}) {
        cull_ptp_scalar(batch.view(), below.object_to_clip, below.alpha, rule, cpu.data());
        c.cull_ptp(below.object_to_clip, below.alpha, rule, &gpu);
        EXPECT_EQ(gpu, cpu);
    }
    // Sets that do not fill a work group, and the empty set.
    for (std::size_t n : {std::size_t{1}, std::size_t{7}, std::size_t{9}, std::size_t{0}}) {
        std::vector<BezierPatch> some(teapot.begin(), teapot.begin() + static_cast<std::ptrdiff_t>(n));
        c.set_patches(some);
        const PatchBatch b = make_batch(some);
        std::vector<std::uint8_t> cc(n);
        for (const BackpatchMethod m : {BackpatchMethod::tcone, BackpatchMethod::ncone, BackpatchMethod::ptp}) {
            const Vec3 eye{0.3f, 0.2f, -8};
            if (m == BackpatchMethod::tcone) cull_tcone_scalar(b.view(), eye, cc.data());
            if (m == BackpatchMethod::ncone) cull_ncone_scalar(b.view(), eye, cc.data());
            if (m == BackpatchMethod::ptp)
                cull_ptp_scalar(b.view(), below.object_to_clip, below.alpha, PtpRule::pcnt, cc.data());
            c.cull(m, below.object_to_clip, eye, below.alpha, PtpRule::pcnt, &gpu);
            EXPECT_EQ(gpu, cc) << backpatch_method_name(m) << " with " << n << " patches";
        }
    }
}

TEST(BackpatchGpu, ReadsAnExistingPatchBuffer) {
    BackpatchCuller& owner = culler();
    const std::vector<BezierPatch> patches = test::split_teapot(1);
    owner.set_patches(patches);
    const Vec3 eye{2, -5, 4};
    std::vector<std::uint8_t> want, got;
    owner.cull_tcone(eye, &want);  // tcone: compiles fastest on llvmpipe (ncone takes ~8 s cold)
    BackpatchCuller other(test::context());
    other.use_patch_buffer(owner.patch_buffer(), patches.size());
    EXPECT_EQ(other.patch_buffer(), owner.patch_buffer());
    EXPECT_EQ(other.patch_count(), patches.size());
    other.cull_tcone(eye, &got);
    EXPECT_EQ(got, want);
    EXPECT_GT(std::count(got.begin(), got.end(), 1), 0);
    EXPECT_THROW(other.use_patch_buffer(owner.patch_buffer(), patches.size() + 1), Error);
    EXPECT_THROW(other.use_patch_buffer(0, 1), Error);
}

}  // namespace
}  // namespace patchcull::gl
