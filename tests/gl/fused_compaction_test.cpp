// The compaction fused into the flag chain's last stage (gl_passes.h's CullStatusPass::end with a
// DrawListBuffers, cull_status.comp.glsl's PC_STATUS_APPEND; gl_pipeline.h's
// CompactMethod::fused_append): on random flag words as the tests leave them (every reason, every
// status), the fused end leaves the same flag words and counters as the plain end, and lists
// exactly the set CompactPass's atomic append lists after it (sorted and compared, and compared
// with the CPU's selection), with the same commands and draw count word for word, for every draw
// selection, K, odd offsets, ranges of 0, 1, odd sizes and more than 65535 work groups. Then the
// pipeline: fused frames equal atomic-append frames (statistics, flag words, id image) with and
// without objects, gaps and object-culled spans (CompactPass's fallback), in two passes and one;
// and `render --draw indirect --compact fused --verify` under the strict test.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"
#include "gl_test_util.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_compaction.h"
#include "patchcull/gl/gl_pipeline.h"
#include "shared.h"

namespace patchcull::gl {
namespace {

namespace fsh = shared;

struct FusedSelection {
    const char* name;
    std::uint32_t mask, value;
};
const FusedSelection kFusedSelections[] = {
    {"second pass", fsh::kDrawMaskSecondPass, fsh::kDrawValueSecondPass},
    {"first pass", fsh::kDrawMaskFirstPass, fsh::kDrawValueFirstPass},
    {"unculled", fsh::kDrawMaskUnculled, fsh::kDrawValueUnculled},
    {"every patch", 0u, 0u},
};

// Flag words as the tests leave them before the end: a reason (none, or one of the four) and a
// status (any of the four combinations).
std::vector<std::uint32_t> fused_random_flags(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    const std::uint32_t reasons[] = {0u, fsh::kCullFrustum, fsh::kCullBackPatch, fsh::kCullOcclusion, fsh::kCullObject};
    const std::uint32_t statuses[] = {0u, fsh::kStatusVisible, fsh::kStatusNewlyVisible,
                                      fsh::kStatusVisible | fsh::kStatusNewlyVisible};
    std::vector<std::uint32_t> flags(n);
    for (auto& f : flags) f = reasons[rng() % 5] | statuses[rng() % 4];
    return flags;
}

// The CPU's end (cull_status.comp.glsl) and selection over [first, first + count).
std::vector<std::uint32_t> fused_cpu_list(std::vector<std::uint32_t> flags, std::size_t first, std::size_t count,
                                          const FusedSelection& s) {
    std::vector<std::uint32_t> out;
    for (std::size_t p = first; p < first + count; ++p) {
        const std::uint32_t reason = flags[p] & fsh::kCullReasonMask;
        const bool was_visible = (flags[p] & fsh::kStatusVisible) != 0;
        const std::uint32_t word =
            reason != 0 ? reason : fsh::kStatusVisible | (was_visible ? 0u : fsh::kStatusNewlyVisible);
        if ((word & s.mask) == s.value) out.push_back(static_cast<std::uint32_t>(p));
    }
    return out;
}

GLuint fused_buffer(const std::vector<std::uint32_t>& words) {
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferData(b, static_cast<GLsizeiptr>(std::max<std::size_t>(words.size(), 1) * 4),
                      words.empty() ? nullptr : words.data(), GL_DYNAMIC_DRAW);
    return b;
}

std::vector<std::uint32_t> fused_read(GLuint b, std::size_t words) {
    std::vector<std::uint32_t> out(words);
    if (words) glGetNamedBufferSubData(b, 0, static_cast<GLsizeiptr>(words * 4), out.data());
    return out;
}

constexpr std::uint32_t kFusedSentinel = 0xDEADBEEFu;

// Plain end + CompactPass (atomic append) on one copy of flags, the fused end on another: flag
// words, counters, commands and draw counts equal word for word (sentinels around them kept), the
// lists the same set, the CPU's. The outputs sit at odd places (list from entry 3, commands from
// byte 20, draw count at byte 8, or none).
void check_fused_end(CullStatusPass& status, CompactPass& compact, const std::vector<std::uint32_t>& flags,
                     std::size_t first, std::size_t count, const FusedSelection& s, std::size_t k, bool with_count,
                     const std::string& label) {
    const std::size_t list_first = 3, list_words = list_first + count + 2;
    const std::size_t commands = compact_command_count(count, k);
    const std::size_t command_words = 5 + 4 * commands + 1;
    struct Side {
        GLuint flags, counters, list, command, draw_count;
    };
    Side sides[2];
    for (Side& side : sides) {
        side.flags = fused_buffer(flags);
        side.counters = fused_buffer(std::vector<std::uint32_t>(fsh::kCounterCount, 0u));
        side.list = fused_buffer(std::vector<std::uint32_t>(list_words, kFusedSentinel));
        side.command = fused_buffer(std::vector<std::uint32_t>(command_words, kFusedSentinel));
        side.draw_count = fused_buffer(std::vector<std::uint32_t>(4, kFusedSentinel));
    }
    for (int fused = 0; fused < 2; ++fused) {
        const Side& side = sides[fused];
        const PatchBuffers patches{0, side.flags, 0, first, count};
        const DrawListBuffers out{side.list, list_first, side.command, 20, with_count ? side.draw_count : 0u, 8, k};
        if (fused) {
            status.end(patches, side.counters, 0, out, s.mask, s.value);
        } else {
            status.end(patches, side.counters, 0);
            compact.run(patches, s.mask, s.value, out, CompactMethod::atomic_append);
        }
        ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR)) << label;
    }
    const std::vector<std::uint32_t> expected = fused_cpu_list(flags, first, count, s);
    const std::size_t n = expected.size();
    EXPECT_TRUE(fused_read(sides[0].flags, flags.size()) == fused_read(sides[1].flags, flags.size()))
        << label << ": flag words";
    EXPECT_TRUE(fused_read(sides[0].counters, fsh::kCounterCount) == fused_read(sides[1].counters, fsh::kCounterCount))
        << label << ": counters";
    const std::vector<std::uint32_t> cmd = fused_read(sides[1].command, command_words);
    EXPECT_TRUE(fused_read(sides[0].command, command_words) == cmd) << label << ": commands";
    EXPECT_TRUE(fused_read(sides[0].draw_count, 4) == fused_read(sides[1].draw_count, 4)) << label << ": draw count";
    // The commands themselves (so that both sides cannot be wrong alike): their patches sum to n.
    std::size_t listed = 0;
    for (std::size_t c = 0; c < commands; ++c) listed += cmd[5 + 4 * c] / 16;
    EXPECT_EQ(listed, n) << label;
    std::vector<std::uint32_t> lists[2];
    for (int side = 0; side < 2; ++side) {
        const std::vector<std::uint32_t> all = fused_read(sides[side].list, list_words);
        for (std::size_t e = 0; e < list_first; ++e) ASSERT_EQ(all[e], kFusedSentinel) << label << " entry " << e;
        for (std::size_t e = list_first + n; e < list_words; ++e)
            ASSERT_EQ(all[e], kFusedSentinel) << label << " entry " << e;
        lists[side].assign(all.begin() + static_cast<std::ptrdiff_t>(list_first),
                           all.begin() + static_cast<std::ptrdiff_t>(list_first + n));
        std::sort(lists[side].begin(), lists[side].end());
    }
    ASSERT_TRUE(lists[1] == lists[0]) << label << ": the fused list differs from CompactPass's";
    ASSERT_TRUE(lists[1] == expected) << label << ": the fused list differs from the CPU's selection";
    for (const Side& side : sides) {
        const GLuint b[] = {side.flags, side.counters, side.list, side.command, side.draw_count};
        glDeleteBuffers(5, b);
    }
}

}  // namespace

TEST(FusedCompaction, EndListsWhatCompactPassListsAfterIt) {
    CullStatusPass status(test::passes());
    CompactPass compact(test::passes());
    const std::vector<std::uint32_t> flags = fused_random_flags(30000, 5);
    struct Case {
        std::size_t first, count, k;
    };
    // Empty, single, one group less / more (64 a group), odd sizes, first > 0, K none, 1, odd,
    // llvmpipe's 226, past the range.
    const Case cases[] = {{0, 0, 0},      {11, 0, 7},        {0, 1, 0},      {29999, 1, 1},
                          {5, 63, 0},     {9, 65, 7},        {1, 4097, 15},  {0, 300, 1},
                          {2, 999, 5000}, {333, 12345, 226}, {17, 29983, 0}, {0, 30000, 226}};
    for (const Case& c : cases)
        for (const FusedSelection& s : kFusedSelections)
            for (const bool with_count : {true, false})
                check_fused_end(status, compact, flags, c.first, c.count, s, c.k, with_count,
                                std::string(s.name) + " [" + std::to_string(c.first) + ", +" + std::to_string(c.count) +
                                    ") K " + std::to_string(c.k) + (with_count ? "" : " no count"));
}

// More than 65535 work groups of 64: the end's range is split into dispatches that append to one total.
TEST(FusedCompaction, RangesOfSeveralDispatchesAppendToOneTotal) {
    CullStatusPass status(test::passes());
    CompactPass compact(test::passes());
    const std::size_t n = 65535 * 64 + 1001;
    const std::vector<std::uint32_t> flags = fused_random_flags(n + 7, 9);
    check_fused_end(status, compact, flags, 7, n, kFusedSelections[0], 226, true, "4.2M second pass");
}

TEST(FusedCompaction, BadOutputsAreRefusedAsCompactPassRefusesThem) {
    CullStatusPass status(test::passes());
    const std::vector<std::uint32_t> flags = fused_random_flags(100, 3);
    const GLuint f = fused_buffer(flags), small = fused_buffer(std::vector<std::uint32_t>(10, 0u)),
                 big = fused_buffer(std::vector<std::uint32_t>(400, 0u));
    const PatchBuffers patches{0, f, 0, 0, 100};
    auto refused = [&](const DrawListBuffers& out, const std::string& what) {
        try {
            status.end(patches, 0, 0, out, fsh::kDrawMaskSecondPass, fsh::kDrawValueSecondPass);
            ADD_FAILURE() << "accepted: " << what;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("GL: CullStatusPass: "), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    refused({small, 0, big, 0, 0, 0, 0}, "draw-list");
    refused({big, 0, small, 32, 0, 0, 0}, "indirect-command");
    refused({big, 0, big, 2, 0, 0, 0}, "command offset 2");
    refused({big, 0, big, 0, big, 6, 0}, "draw-count offset 6");
    const GLuint b[] = {f, small, big};
    glDeleteBuffers(3, b);
}

namespace {

// A frame of the teapot seen from angle a (radians) around it.
PipelineParams fused_frame(float a, CullMode mode, CompactMethod method) {
    PipelineParams p;
    RenderParams& rp = p.frame.render;
    rp.view = look_at({8 * std::sin(a), -8 * std::cos(a), 4}, {0, 0, 1.5f}, {0, 0, 1});
    rp.projection = perspective(0.9f, 1.0f, 0.5f, 40.0f);
    rp.width = rp.height = 96;
    rp.tess_level = 2;
    p.frame.cull = mode;
    p.frame.timing = TimingMethod::off;
    p.draw = DrawMode::indirect;
    p.compact = method;
    return p;
}

}  // namespace

// Fused frames equal atomic-append frames: every count, the patches each pass submitted, the flag
// words and the id image, for two passes and one, aggressive, with one object, objects and gaps
// (one object not culled), and object-culled spans (CompactPass lists those frames); the
// tessellation level changes from frame to frame (and with it the commands' K).
TEST(FusedCompaction, PipelineFramesEqualTheAtomicAppends) {
    const std::vector<BezierPatch> patches = test::split_teapot(1);  // 128 patches
    CullPipeline append(test::context()), fused(test::context());
    append.set_patches(patches);
    fused.set_patches(patches);
    struct Layout {
        const char* name;
        std::vector<ObjectRange> objects;
        std::vector<PatchSpan> culled;
    };
    const Layout layouts[] = {
        {"whole set", {}, {}},
        {"objects and gaps", {{0, 40, true}, {50, 60, false}, {110, 10, true}}, {}},
        {"object-culled spans", {{0, 64, true}, {64, 64, true}}, {{10, 20}, {90, 5}}},
    };
    std::size_t pass2_listed = 0, one_pass_listed = 0;
    for (const Layout& layout : layouts)
        for (const CullMode mode : {CullMode::all, CullMode::frustum, CullMode::backpatch})
            for (const bool aggressive : {false, true}) {
                append.reset_visibility();
                fused.reset_visibility();
                for (int f = 0; f < 3; ++f) {
                    const std::string where = std::string(layout.name) + " " + cull_mode_name(mode) +
                                              (aggressive ? " aggressive" : "") + " frame " + std::to_string(f);
                    FrameStats s[2];
                    int side = 0;
                    for (CullPipeline* pipeline : {&append, &fused}) {
                        PipelineParams p =
                            fused_frame(0.6f * static_cast<float>(f), mode,
                                        side ? CompactMethod::fused_append : CompactMethod::atomic_append);
                        p.frame.aggressive = aggressive;
                        // A level per frame: K (commands of at most K patches) follows the frame's.
                        p.frame.render.tess_level = f == 1 ? 8 : 2 + f;
                        p.objects = layout.objects;
                        p.object_culled = layout.culled;
                        s[side++] = pipeline->render_frame(p);
                    }
                    EXPECT_EQ(s[1].pass1_submitted, s[0].pass1_submitted) << where;
                    EXPECT_EQ(s[1].pass2_submitted, s[0].pass2_submitted) << where;
                    EXPECT_EQ(s[1].pass1_drawn, s[0].pass1_drawn) << where;
                    EXPECT_EQ(s[1].pass2_drawn, s[0].pass2_drawn) << where;
                    EXPECT_EQ(s[1].pass1_submitted, s[1].pass1_drawn) << where;
                    EXPECT_EQ(s[1].pass2_submitted, s[1].pass2_drawn) << where;
                    EXPECT_EQ(s[1].visible, s[0].visible) << where;
                    EXPECT_EQ(s[1].newly_visible, s[0].newly_visible) << where;
                    EXPECT_EQ(s[1].occlusion_culled, s[0].occlusion_culled) << where;
                    EXPECT_TRUE(fused.renderer().read_cull_flags() == append.renderer().read_cull_flags()) << where;
                    EXPECT_TRUE(fused.renderer().read_ids() == append.renderer().read_ids()) << where;
                    if (s[1].two_pass)
                        pass2_listed += s[1].pass2_submitted;
                    else
                        one_pass_listed += s[1].pass1_submitted;
                }
            }
    EXPECT_GT(pass2_listed, 0u);
    EXPECT_GT(one_pass_listed, 0u);
}

namespace {

// `render ARGS --size 96x64 --draw indirect --compact fused --verify --json`: exit 0, "compact"
// reported, and in every frame 0 false culls, only depth ties differ from the reference, and
// the patches submitted are the patches drawn. Returns the patches submitted in pass 2.
long fused_render(const std::string& args) {
    const std::string command = "render " + args + " --size 96x64 --draw indirect --compact fused --verify --json";
    const cli_test::CliRun r = cli_test::run(command);
    EXPECT_EQ(r.status, 0) << command << "\n" << r.err;
    if (r.out.empty()) return 0;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["compact"], "fused") << command;
    long pass2 = 0;
    for (const nlohmann::json& f : j["frames"]) {
        const std::string where = command + ", frame " + f["frame"].dump();
        const long submitted = f["submitted"]["pass1"].get<long>() + f["submitted"]["pass2"].get<long>();
        const long drawn = f["pass1_drawn"].get<long>() + f["pass2_drawn"].get<long>();
        pass2 += f["submitted"]["pass2"].get<long>();
        EXPECT_EQ(f["false_culls"], 0) << where;
        EXPECT_EQ(f["differing_pixels"], f["depth_ties"]) << where;
        EXPECT_EQ(submitted, drawn) << where;
        EXPECT_GT(drawn, 0) << where;
    }
    return pass2;
}

}  // namespace

// The default scene in two passes (pass 2 listed by the chain's end) and one pass, the fused cull
// pass, --cull auto's objects (several spans, some not culled), and the object level (frames
// with object-culled spans fall back to CompactPass).
TEST(FusedCompaction, RenderCompactFusedVerifiesStrictly) {
    EXPECT_GT(fused_render("default --frames 3 --tess 4"), 0);
    fused_render("default --frames 2 --tess 2 --cull frustum");
    fused_render("default --frames 1 --tess 2 --scheme osd --fused-pass");
    fused_render("default --frames 3 --tess 2 --cull auto");
    fused_render(std::string(PATCHCULL_SOURCE_DIR) + "/data/scenes/city_small.json --frames 2 --tess 2 --objects bvh");
}

}  // namespace patchcull::gl
