// CompactPass (gl_compaction.h, shaders/compact.comp.glsl): on random flag words (every reason and
// status), for every draw selection of shared.h, the list holds the patches the CPU selects (as a
// set for the atomic append, in ascending order for the prefix scan), and the indirect command and
// the draw count are right; ranges with first > 0, of 0, 1, odd and several million patches. Then
// the draw itself: a compacted glMultiDrawArraysIndirect(Count) of a patch-pulling tessellation
// program gives the same id image as the flag path (all patches issued, levels 0 for the culled).
// With at most K patches a command: ceil(count / K) commands, the empty ones past the survivors.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_compaction.h"
#include "shared.h"

namespace patchcull::gl {
namespace {

namespace sh = shared;

struct Selection {
    const char* name;
    std::uint32_t mask, value;
};
const Selection kSelections[] = {
    {"unculled", sh::kDrawMaskUnculled, sh::kDrawValueUnculled},
    {"first pass", sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass},
    {"second pass", sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass},
    {"every patch", 0u, 0u},
};
const CompactMethod kMethods[] = {CompactMethod::atomic_append, CompactMethod::prefix_scan};

// Flag words as the chain leaves them: a reason (none, or one of the four) and a status (any of
// the four combinations of kStatusVisible and kStatusNewlyVisible).
std::vector<std::uint32_t> random_flags(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    const std::uint32_t reasons[] = {0u, sh::kCullFrustum, sh::kCullBackPatch, sh::kCullOcclusion, sh::kCullObject};
    const std::uint32_t statuses[] = {0u, sh::kStatusVisible, sh::kStatusNewlyVisible,
                                      sh::kStatusVisible | sh::kStatusNewlyVisible};
    std::vector<std::uint32_t> flags(n);
    for (auto& f : flags) f = reasons[rng() % 5] | statuses[rng() % 4];
    return flags;
}

std::vector<std::uint32_t> cpu_select(const std::vector<std::uint32_t>& flags, std::size_t first, std::size_t count,
                                      const Selection& s) {
    std::vector<std::uint32_t> out;
    for (std::size_t p = first; p < first + count; ++p)
        if ((flags[p] & s.mask) == s.value) out.push_back(static_cast<std::uint32_t>(p));
    return out;
}

class Buffer {
public:
    explicit Buffer(const std::vector<std::uint32_t>& words) {
        test::passes();
        glCreateBuffers(1, &name_);
        glNamedBufferData(name_, static_cast<GLsizeiptr>(std::max<std::size_t>(words.size(), 1) * 4),
                          words.empty() ? nullptr : words.data(), GL_DYNAMIC_DRAW);
    }
    ~Buffer() { glDeleteBuffers(1, &name_); }
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;
    GLuint name() const { return name_; }
    std::vector<std::uint32_t> read(std::size_t first_word, std::size_t count) const {
        std::vector<std::uint32_t> out(count);
        if (count)
            glGetNamedBufferSubData(name_, static_cast<GLintptr>(first_word * 4), static_cast<GLsizeiptr>(count * 4),
                                    out.data());
        return out;
    }
    void fill(std::size_t words, std::uint32_t value) const {
        const std::vector<std::uint32_t> v(words, value);
        glNamedBufferSubData(name_, 0, static_cast<GLsizeiptr>(words * 4), v.data());
    }

private:
    GLuint name_ = 0;
};

constexpr std::uint32_t kSentinel = 0xDEADBEEFu;

// Runs the pass over flags[first, first + count) and checks list, commands and draw count against
// the CPU's selection. The outputs sit at odd places: the list from entry list_first, the commands
// from byte 20 (not 16-aligned), the draw count at byte 8; the words around them keep the
// sentinel. per_command: DrawListBuffers::patches_per_command (0: one command).
void check_compaction(CompactPass& pass, const Buffer& flags_buffer, const std::vector<std::uint32_t>& flags,
                      std::size_t first, std::size_t count, const Selection& s, CompactMethod method,
                      const std::string& label, std::size_t per_command = 0) {
    const std::size_t list_first = 3;
    const std::size_t list_words = list_first + count + 2;
    const std::size_t commands = compact_command_count(count, per_command);
    const std::size_t command_words = 5 + 4 * commands + 1;
    Buffer list(std::vector<std::uint32_t>(list_words, kSentinel));
    Buffer command(std::vector<std::uint32_t>(command_words, kSentinel));
    Buffer draw_count(std::vector<std::uint32_t>(4, kSentinel));
    const PatchBuffers patches{0, flags_buffer.name(), 0, first, count};
    const DrawListBuffers out{list.name(), list_first, command.name(), 20, draw_count.name(), 8, per_command};
    pass.run(patches, s.mask, s.value, out, method);
    ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

    const std::vector<std::uint32_t> expected = cpu_select(flags, first, count, s);
    const std::size_t n = expected.size();
    const std::size_t k = per_command == 0 ? std::max<std::size_t>(count, 1) : per_command;
    const std::vector<std::uint32_t> cmd = command.read(0, command_words);
    for (std::size_t c = 0; c < commands; ++c) {
        const std::size_t start = c * k, m = n > start ? std::min(k, n - start) : 0;
        const std::uint32_t* w = &cmd[5 + 4 * c];
        EXPECT_EQ(w[0], 16u * m) << label << " command " << c;
        EXPECT_EQ(w[1], 1u) << label << " command " << c;
        EXPECT_EQ(w[2], 16u * (list_first + start)) << label << " command " << c;
        EXPECT_EQ(w[3], 0u) << label << " command " << c;
    }
    for (std::size_t w :
         {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{4}, command_words - 1})
        EXPECT_EQ(cmd[w], kSentinel) << label << " command word " << w;
    const std::vector<std::uint32_t> dc = draw_count.read(0, 4);
    EXPECT_EQ(dc[2], (n + k - 1) / k) << label;
    EXPECT_EQ(dc[0], kSentinel) << label;
    EXPECT_EQ(dc[3], kSentinel) << label;

    const std::vector<std::uint32_t> all = list.read(0, list_words);
    for (std::size_t e = 0; e < list_first; ++e) ASSERT_EQ(all[e], kSentinel) << label << " entry " << e;
    for (std::size_t e = list_first + n; e < list_words; ++e) ASSERT_EQ(all[e], kSentinel) << label << " entry " << e;
    std::vector<std::uint32_t> got(all.begin() + static_cast<std::ptrdiff_t>(list_first),
                                   all.begin() + static_cast<std::ptrdiff_t>(list_first + n));
    if (method == CompactMethod::atomic_append) std::sort(got.begin(), got.end());
    ASSERT_TRUE(got == expected) << label << ": the list differs from the CPU's selection";
}

}  // namespace

TEST(GpuCompaction, ListCommandAndCountMatchTheCpuSelection) {
    CompactPass pass(test::passes());
    const std::vector<std::uint32_t> flags = random_flags(80000, 7);
    Buffer flags_buffer(flags);
    struct Range {
        std::size_t first, count;
    };
    // Empty, single, one group less/more, several groups, more than 256 groups (the scan of the
    // sums loops), odd sizes, first > 0, and both sides of the scan's one-work-group limit
    // (kCompactSingleGroupPatches = 16384: whole chunks of 2048, and one patch past it).
    static_assert(sh::kCompactSingleGroupPatches == 16384);
    const Range ranges[] = {{0, 0},    {11, 0},   {0, 1},       {79999, 1}, {5, 255},   {0, 256},   {9, 257},
                            {0, 2048}, {1, 4097}, {333, 12345}, {0, 16384}, {3, 16385}, {0, 80000}, {17, 79983}};
    for (const Range& r : ranges)
        for (const Selection& s : kSelections)
            for (const CompactMethod m : kMethods)
                check_compaction(pass, flags_buffer, flags, r.first, r.count, s, m,
                                 std::string(compact_method_name(m)) + " " + s.name + " [" + std::to_string(r.first) +
                                     ", +" + std::to_string(r.count) + ")");
}

// DrawListBuffers::patches_per_command = K: ceil(count / K) commands of at most K patches, those
// past the survivors empty, the draw count ceil(n / K); K of 1 (one command per patch), odd, equal
// to and past the range, and a range whose commands need more than one work group.
TEST(GpuCompaction, CommandsOfAtMostKPatches) {
    EXPECT_EQ(compact_command_count(0, 0), 1u);
    EXPECT_EQ(compact_command_count(0, 7), 1u);
    EXPECT_EQ(compact_command_count(100, 0), 1u);
    EXPECT_EQ(compact_command_count(100, 7), 15u);
    EXPECT_EQ(compact_command_count(14, 7), 2u);
    CompactPass pass(test::passes());
    const std::vector<std::uint32_t> flags = random_flags(20000, 17);
    Buffer flags_buffer(flags);
    struct Case {
        std::size_t first, count, k;
    };
    const Case cases[] = {{0, 0, 5},     {4, 1, 1},      {9, 300, 1},    {0, 257, 7},    {13, 4097, 15},
                          {2, 999, 999}, {2, 999, 5000}, {1, 19999, 60}, {0, 20000, 226}};
    for (const Case& c : cases)
        for (const Selection& s : kSelections)
            for (const CompactMethod m : kMethods)
                check_compaction(pass, flags_buffer, flags, c.first, c.count, s, m,
                                 std::string(compact_method_name(m)) + " " + s.name + " [" + std::to_string(c.first) +
                                     ", +" + std::to_string(c.count) + ") K " + std::to_string(c.k),
                                 c.k);
}

TEST(GpuCompaction, ScanIsTheSameEveryRunAndAppendHoldsTheSameSet) {
    CompactPass pass(test::passes());
    const std::size_t n = 50001;
    const std::vector<std::uint32_t> flags = random_flags(n, 11);
    Buffer flags_buffer(flags);
    const PatchBuffers patches{0, flags_buffer.name(), 0, 0, n};
    Buffer list(std::vector<std::uint32_t>(n, 0u)), command(std::vector<std::uint32_t>(4, 0u));
    const DrawListBuffers out{list.name(), 0, command.name(), 0, 0, 0};
    std::vector<std::uint32_t> scans[2], appends[2];
    for (int run = 0; run < 2; ++run) {
        pass.run(patches, sh::kDrawMaskUnculled, sh::kDrawValueUnculled, out, CompactMethod::prefix_scan);
        scans[run] = list.read(0, command.read(0, 1)[0] / 16);
        pass.run(patches, sh::kDrawMaskUnculled, sh::kDrawValueUnculled, out, CompactMethod::atomic_append);
        appends[run] = list.read(0, command.read(0, 1)[0] / 16);
        std::sort(appends[run].begin(), appends[run].end());
    }
    EXPECT_FALSE(scans[0].empty());
    EXPECT_TRUE(std::is_sorted(scans[0].begin(), scans[0].end()));
    EXPECT_TRUE(scans[0] == scans[1]);
    EXPECT_TRUE(appends[0] == scans[0]);
    EXPECT_TRUE(appends[1] == scans[0]);
}

TEST(GpuCompaction, MillionsOfPatches) {
    CompactPass pass(test::passes());
    const std::size_t total = 2'600'001, first = 3, count = total - first;
    const std::vector<std::uint32_t> flags = random_flags(total, 5);
    Buffer flags_buffer(flags);
    const Selection& s = kSelections[0];
    GLint64 block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
    std::printf("GL_MAX_SHADER_STORAGE_BLOCK_SIZE: %lld bytes\n", static_cast<long long>(block));
    for (const CompactMethod m : kMethods) {
        const auto t0 = std::chrono::steady_clock::now();
        check_compaction(pass, flags_buffer, flags, first, count, s, m, std::string(compact_method_name(m)) + " 2.6M");
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::printf("%s over %zu patches: %.0f ms with the checks\n", std::string(compact_method_name(m)).c_str(),
                    count, ms);
    }
}

// Past one dispatch: the append covers 65535 work groups of 256 patches a dispatch (the scan 65535
// of 2048, past llvmpipe's storage-block size, so its split is not reached here).
TEST(GpuCompaction, AppendSplitsPastOneDispatch) {
    CompactPass pass(test::passes());
    const std::size_t first = 5, count = 65535u * sh::kCompactGroupSize + 1001;
    const std::vector<std::uint32_t> flags = random_flags(first + count, 13);
    Buffer flags_buffer(flags);
    check_compaction(pass, flags_buffer, flags, first, count, kSelections[0], CompactMethod::atomic_append,
                     "atomic, two dispatches");
}

TEST(GpuCompaction, BadBuffersAreOneLineErrors) {
    CompactPass pass(test::passes());
    Buffer flags_buffer(std::vector<std::uint32_t>(100, 0u));
    Buffer small(std::vector<std::uint32_t>(3, 0u)), big(std::vector<std::uint32_t>(200, 0u));
    const PatchBuffers patches{0, flags_buffer.name(), 0, 0, 100};
    const auto message = [&](const DrawListBuffers& out, const PatchBuffers& p) -> std::string {
        try {
            pass.run(p, 0u, 0u, out);
        } catch (const Error& e) {
            return e.what();
        }
        return "";
    };
    const std::string cases[] = {
        message({small.name(), 0, big.name(), 0, 0, 0}, patches),            // list too small
        message({big.name(), 150, big.name(), 0, 0, 0}, patches),            // list_first + count past the list
        message({big.name(), 0, small.name(), 0, 0, 0}, patches),            // command too small
        message({big.name(), 0, big.name(), 2, 0, 0}, patches),              // command offset
        message({big.name(), 0, big.name(), 0, small.name(), 12}, patches),  // draw count past its buffer
        message({big.name(), 0, big.name(), 0, big.name(), 6}, patches),     // draw-count offset
        message({0, 0, big.name(), 0, 0, 0}, patches),                       // no list
        message({big.name(), 0, big.name(), 0, 0, 0}, {0, flags_buffer.name(), 0, 50, 100}),  // flags
        message({big.name(), 0, big.name(), 0, 0, 0, 1}, patches),  // 100 commands: 1600 bytes, the buffer 800
    };
    for (const std::string& m : cases) {
        EXPECT_EQ(m.rfind("GL: CompactPass: ", 0), 0u) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

namespace {

// The tiny patch-pulling program: patch p is an axis-aligned square (its corner points 0, 3, 12,
// 15, bilinear), and the fragment writes p + 1. compacted: the vertex shader finds its patch in
// the draw list; else gl_VertexID / 16 and the TCS skips the patches the selection drops.
GLuint compile(GLenum stage, const std::string& body) {
    const std::string text = "#version 450 core\n" + std::string(shipped_glsl("shared.h")) + body;
    const char* source = text.c_str();
    const GLuint s = glCreateShader(stage);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024] = {};
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        ADD_FAILURE() << "shader: " << log;
    }
    return s;
}

GLuint id_program(bool compacted) {
    const std::string points = R"(
layout(std430, binding = kBindingControlPoints) readonly buffer Points { vec4 control_points[]; };
)";
    const std::string vs = compacted ? points + std::string(shipped_glsl("patchcull_draw_list.h")) + R"(
flat out uint v_patch;
void main() {
    v_patch = patchcull_draw_list_patch(gl_VertexID);
    gl_Position = control_points[16u * v_patch + patchcull_draw_list_point(gl_VertexID)];
}
)"
                                     : points + R"(
flat out uint v_patch;
void main() {
    v_patch = uint(gl_VertexID) / 16u;
    gl_Position = control_points[gl_VertexID];
}
)";
    const std::string tcs = (compacted ? std::string() : std::string(shipped_glsl("patchcull_tcs.h"))) + R"(
layout(vertices = 16) out;
flat in uint v_patch[];
patch out uint tc_patch;
uniform uint u_mask, u_value;
void main() {
    gl_out[gl_InvocationID].gl_Position = gl_in[gl_InvocationID].gl_Position;
    if (gl_InvocationID == 0) {
        tc_patch = v_patch[0];
        gl_TessLevelOuter[0] = 1.0; gl_TessLevelOuter[1] = 1.0;
        gl_TessLevelOuter[2] = 1.0; gl_TessLevelOuter[3] = 1.0;
        gl_TessLevelInner[0] = 1.0; gl_TessLevelInner[1] = 1.0;
)" + (compacted ? "" : "        if (!patchcull_patch_drawn(v_patch[0], u_mask, u_value)) patchcull_skip_patch();\n") +
                            R"(    }
}
)";
    const std::string tes = R"(
layout(quads, equal_spacing, ccw) in;
patch in uint tc_patch;
flat out uint te_patch;
void main() {
    te_patch = tc_patch;
    vec4 a = mix(gl_in[0].gl_Position, gl_in[3].gl_Position, gl_TessCoord.x);
    vec4 b = mix(gl_in[12].gl_Position, gl_in[15].gl_Position, gl_TessCoord.x);
    gl_Position = mix(a, b, gl_TessCoord.y);
}
)";
    const std::string fs = R"(
flat in uint te_patch;
layout(location = 0) out uint o_id;
void main() { o_id = te_patch + 1u; }
)";
    const GLuint program = glCreateProgram();
    const GLuint shaders[] = {compile(GL_VERTEX_SHADER, vs), compile(GL_TESS_CONTROL_SHADER, tcs),
                              compile(GL_TESS_EVALUATION_SHADER, tes), compile(GL_FRAGMENT_SHADER, fs)};
    for (GLuint s : shaders) glAttachShader(program, s);
    glLinkProgram(program);
    for (GLuint s : shaders) glDeleteShader(s);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    EXPECT_TRUE(ok) << "id program did not link";
    return program;
}

}  // namespace

TEST(GpuCompaction, CompactedDrawGivesTheFlagPathsIdImage) {
    test::passes();
    constexpr int kW = 64, kH = 48, kCols = 8, kRows = 6;
    constexpr std::size_t kPatches = kCols * kRows;
    // Patch p covers its own 8 x 8 pixel cell of the 64 x 48 image (nothing overlaps, so the image
    // does not depend on the order of the list).
    std::vector<float> points(16 * 4 * kPatches);
    for (std::size_t p = 0; p < kPatches; ++p) {
        const std::size_t cell_col = p % kCols, cell_row = p / kCols;
        const float x0 = -1.0f + 2.0f * static_cast<float>(cell_col) / kCols;
        const float y0 = -1.0f + 2.0f * static_cast<float>(cell_row) / kRows;
        for (int k = 0; k < 16; ++k) {
            float* v = &points[4 * (16 * p + static_cast<std::size_t>(k))];
            const int col = k % 4, row = k / 4;
            v[0] = x0 + (2.0f / kCols) * static_cast<float>(col) / 3.0f;
            v[1] = y0 + (2.0f / kRows) * static_cast<float>(row) / 3.0f;
            v[2] = 0.0f;
            v[3] = 1.0f;
        }
    }
    GLuint cp = 0, fbo = 0, color = 0, vao = 0;
    glCreateBuffers(1, &cp);
    glNamedBufferData(cp, static_cast<GLsizeiptr>(points.size() * 4), points.data(), GL_STATIC_DRAW);
    glCreateTextures(GL_TEXTURE_2D, 1, &color);
    glTextureStorage2D(color, 1, GL_R32UI, kW, kH);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color, 0);
    ASSERT_EQ(glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER), static_cast<GLenum>(GL_FRAMEBUFFER_COMPLETE));
    glCreateVertexArrays(1, &vao);
    const GLuint flag_program = id_program(false), list_program = id_program(true);
    const bool with_count = epoxy_has_gl_extension("GL_ARB_indirect_parameters");
    if (!with_count) std::printf("no GL_ARB_indirect_parameters: glMultiDrawArraysIndirect only\n");

    const std::vector<std::uint32_t> flags = random_flags(kPatches, 3);
    Buffer flags_buffer(flags), list(std::vector<std::uint32_t>(kPatches + 8, 0u)),
        command(std::vector<std::uint32_t>(4 + 4 * kPatches, 0u)), draw_count(std::vector<std::uint32_t>(4, 0u));
    CompactPass pass(test::passes());

    const auto draw = [&](GLuint program, const Selection& s, auto&& issue) {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glViewport(0, 0, kW, kH);
        const GLuint zero[4] = {0, 0, 0, 0};
        glClearBufferuiv(GL_COLOR, 0, zero);
        glDisable(GL_DEPTH_TEST);
        glBindVertexArray(vao);
        glUseProgram(program);
        glUniform1ui(glGetUniformLocation(program, "u_mask"), s.mask);
        glUniform1ui(glGetUniformLocation(program, "u_value"), s.value);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingControlPoints, cp);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingCullFlags, flags_buffer.name());
        glPatchParameteri(GL_PATCH_VERTICES, 16);
        issue();
        std::vector<std::uint32_t> ids(static_cast<std::size_t>(kW) * kH);
        glReadPixels(0, 0, kW, kH, GL_RED_INTEGER, GL_UNSIGNED_INT, ids.data());
        glUseProgram(0);
        glBindVertexArray(0);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        return ids;
    };

    struct Range {
        std::size_t first, count;
    };
    std::size_t compared = 0;
    for (const Range r : {Range{0, kPatches}, Range{5, 37}, Range{47, 1}, Range{9, 0}})
        for (const Selection& s : kSelections)
            for (const CompactMethod m : kMethods)
                for (const std::size_t k : {std::size_t{0}, std::size_t{5}}) {  // one command, or several
                    const std::string label = std::string(compact_method_name(m)) + " " + s.name + " [" +
                                              std::to_string(r.first) + ", +" + std::to_string(r.count) + ") K " +
                                              std::to_string(k);
                    const std::vector<std::uint32_t> reference = draw(flag_program, s, [&] {
                        glDrawArrays(GL_PATCHES, static_cast<GLint>(16 * r.first), static_cast<GLsizei>(16 * r.count));
                    });
                    const PatchBuffers patches{cp, flags_buffer.name(), 0, r.first, r.count};
                    pass.run(patches, s.mask, s.value, {list.name(), 2, command.name(), 16, draw_count.name(), 4, k},
                             m);
                    const auto commands = static_cast<GLsizei>(compact_command_count(r.count, k));
                    for (const bool counted : {false, true}) {
                        if (counted && !with_count) continue;
                        const std::vector<std::uint32_t> ids = draw(list_program, s, [&] {
                            glBindBuffer(GL_DRAW_INDIRECT_BUFFER, command.name());
                            if (counted) {
                                glBindBuffer(GL_PARAMETER_BUFFER_ARB, draw_count.name());
                                glMultiDrawArraysIndirectCountARB(GL_PATCHES, reinterpret_cast<const void*>(16), 4,
                                                                  commands, 0);
                                glBindBuffer(GL_PARAMETER_BUFFER_ARB, 0);
                            } else {
                                glMultiDrawArraysIndirect(GL_PATCHES, reinterpret_cast<const void*>(16), commands, 0);
                            }
                            glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
                        });
                        ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR)) << label;
                        ASSERT_TRUE(ids == reference) << label << (counted ? " (indirect count)" : " (indirect)");
                        // And the image holds exactly the CPU's selection.
                        std::set<std::uint32_t> expected;
                        for (const std::uint32_t p : cpu_select(flags, r.first, r.count, s)) expected.insert(p + 1);
                        ASSERT_TRUE(test::ids_present(ids) == expected) << label;
                        ++compared;
                    }
                }
    EXPECT_GE(compared, 64u);
    glDeleteProgram(flag_program);
    glDeleteProgram(list_program);
    glDeleteVertexArrays(1, &vao);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &color);
    glDeleteBuffers(1, &cp);
}

// Several CompactPass ranges in one command buffer (the pipeline's multi-span draw pass: one range
// per object), drawn as CullPipeline draws them with glMultiDrawArraysIndirectCount: one
// PatchRenderer::draw_indirect per range with that range's own draw count. The commands past a
// range's survivors are poisoned with a command that draws a patch the selection drops, and the
// counted draws still give the flag path's id image and drawn patches. One draw of every command
// without the counts (the fallback without the extension) draws the poison, so the test fails if
// the counts are ignored.
TEST(GpuCompaction, MultiRangeIndirectDrawHonoursEachRangesCount) {
    PatchRenderer r(test::context());
    if (!r.has_indirect_count()) {
        std::printf("no glMultiDrawArraysIndirectCount: nothing to check\n");
        return;
    }
    constexpr int kCols = 8, kRows = 6;
    constexpr std::size_t kPatches = kCols * kRows;
    std::vector<BezierPatch> patches;
    for (int row = 0; row < kRows; ++row)
        for (int col = 0; col < kCols; ++col)
            patches.push_back(test_patches::flat_patch(static_cast<float>(col), static_cast<float>(row), 0.0f, false));
    r.set_patches(patches);
    const std::vector<std::uint32_t> flags = random_flags(kPatches, 11);
    r.set_flag_words(flags);
    RenderParams params;
    params.view = look_at({4, 3, 10}, {4, 3, 0}, {0, 1, 0});
    params.projection = perspective(1.0f, 64.0f / 48.0f, 1.0f, 100.0f);
    params.width = 64;
    params.height = 48;
    params.tess_level = 2;
    const Selection s = kSelections[1];  // first pass
    const std::vector<PatchSpan> spans = {{3, 20}, {30, 15}};
    constexpr std::size_t k = 2;
    const std::size_t commands[2] = {compact_command_count(spans[0].count, k),
                                     compact_command_count(spans[1].count, k)};

    // The poison: a patch of neither range's selection, at list entry kPatches (past every range).
    std::uint32_t poison = 0;
    while (poison < kPatches && (flags[poison] & s.mask) == s.value) ++poison;
    ASSERT_LT(poison, kPatches);
    std::vector<std::uint32_t> list_words(kPatches + 1, 0u);
    list_words[kPatches] = poison;
    Buffer list(list_words), command(std::vector<std::uint32_t>(4 * (commands[0] + commands[1]), 0u)),
        counts(std::vector<std::uint32_t>(2, 0u));
    CompactPass pass(test::passes());
    std::size_t command_first = 0;
    std::vector<IndirectDraw> counted;
    for (std::size_t i = 0; i < spans.size(); ++i) {
        PatchBuffers range = r.patch_buffers();
        range.first = spans[i].first;
        range.count = spans[i].count;
        pass.run(range, s.mask, s.value,
                 {list.name(), spans[i].first, command.name(), command_first * 16, counts.name(), i * 4, k});
        IndirectDraw d;
        d.list = list.name();
        d.commands = command.name();
        d.first_command = command_first;
        d.command_count = commands[i];
        d.draw_count = counts.name();
        d.draw_count_offset = i * 4;
        counted.push_back(d);
        command_first += commands[i];
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    const std::vector<std::uint32_t> n = counts.read(0, 2);
    std::size_t poisoned = 0;
    for (std::size_t i = 0, c0 = 0; i < spans.size(); c0 += commands[i], ++i) {
        ASSERT_LT(n[i], commands[i]) << "range " << i << " has no command past its survivors";
        for (std::size_t c = n[i]; c < commands[i]; ++c, ++poisoned) {
            const std::uint32_t bad[4] = {16u, 1u, 16u * static_cast<std::uint32_t>(kPatches), 0u};
            glNamedBufferSubData(command.name(), static_cast<GLintptr>((c0 + c) * 16), 16, bad);
        }
    }
    ASSERT_GT(poisoned, 0u);

    r.begin_frame(params);
    r.draw_selected(s.mask, s.value, spans);
    const std::vector<std::uint32_t> reference = r.read_ids();
    const std::vector<std::uint8_t> reference_drawn = r.read_drawn_patches();
    ASSERT_EQ(reference_drawn[poison], 0);
    ASSERT_FALSE(test::ids_present(reference).empty());

    r.begin_frame(params);
    for (const IndirectDraw& d : counted) r.draw_indirect(d);
    EXPECT_TRUE(r.read_ids() == reference);
    EXPECT_TRUE(r.read_drawn_patches() == reference_drawn);

    // Without the counts every command is drawn, the poison included: the check above can fail.
    IndirectDraw all;
    all.list = list.name();
    all.commands = command.name();
    all.command_count = commands[0] + commands[1];
    r.begin_frame(params);
    r.draw_indirect(all);
    EXPECT_EQ(r.read_drawn_patches()[poison], 1);
    EXPECT_EQ(test::ids_present(r.read_ids()).count(poison + 1), 1u);
}

}  // namespace patchcull::gl
