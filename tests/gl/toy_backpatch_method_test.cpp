// A toy back-patch method added from this one file, as docs/CONTRIBUTING.md's list says a new
// method is added: its CPU kernel registered in core/backpatch_methods.h and its GPU pass in
// gl/gl_backpatch_passes.h. With nothing else edited, the registry's users pick it up: the
// name parser and the tools' lists (render and view's --backpatch, the viewer, the demo), the
// evaluation (`patchcull cull --methods`), BackpatchCuller and CullPipeline's frame, where it runs
// as its own pass (not fusable). The toy "culls" a patch whose 16 control points all have x < 0:
// not a real back-patch test (the evaluation counts its false culls), just easy to check.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <string>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/eval/cull_eval.h"
#include "patchcull/gl/gl_backpatch.h"
#include "patchcull/gl/gl_backpatch_passes.h"
#include "patchcull/gl/gl_pipeline.h"
#include "shared.h"

namespace patchcull::gl {
namespace {

void toy_kernel(const PatchBatchView& patches, const CullView&, const BackpatchOptions&, std::uint8_t* culled) {
    for (std::size_t i = 0; i < patches.count; ++i) {
        bool all_negative = true;
        for (int k = 0; k < kPatchPoints; ++k) all_negative = all_negative && patches.at(i, k, 0) < 0.0f;
        culled[i] = all_negative ? 1 : 0;
    }
}

// The toy's pass: its own compute shader over the flag chain's buffers, with the constants of the
// shipped shared.h (binding points, reason bits).
class ToyPass final : public BackpatchPass {
public:
    ToyPass() {
        const std::string source = "#version 450\n" + std::string(shipped_glsl("shared.h")) + R"(
layout(local_size_x = 64) in;
layout(std430, binding = kBindingControlPoints) readonly buffer ControlPoints { vec4 cp[]; };
layout(std430, binding = kBindingCullFlags) buffer CullFlags { uint flags[]; };
uniform uint u_first;
uniform uint u_count;
void main() {
    if (gl_GlobalInvocationID.x >= u_count) return;
    uint p = u_first + gl_GlobalInvocationID.x;
    if ((flags[p] & kCullReasonMask) != 0u) return;
    bool all_negative = true;
    for (uint k = 0u; k < 16u; ++k) all_negative = all_negative && cp[16u * p + k].x < 0.0;
    if (all_negative) flags[p] |= kCullBackPatch;
}
)";
        const char* text = source.c_str();
        const GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
        glShaderSource(shader, 1, &text, nullptr);
        glCompileShader(shader);
        GLint ok = 0;
        glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
        EXPECT_TRUE(ok) << "toy shader did not compile";
        program_ = glCreateProgram();
        glAttachShader(program_, shader);
        glLinkProgram(program_);
        glDeleteShader(shader);
    }
    ~ToyPass() override { glDeleteProgram(program_); }
    void run(const PatchBuffers& patches, const CullView&, const BackpatchOptions&) override {
        ++runs;
        glUseProgram(program_);
        glUniform1ui(glGetUniformLocation(program_, "u_first"), static_cast<GLuint>(patches.first));
        glUniform1ui(glGetUniformLocation(program_, "u_count"), static_cast<GLuint>(patches.count));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingControlPoints, patches.control_points);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingCullFlags, patches.flags);
        glDispatchCompute(static_cast<GLuint>((patches.count + 63) / 64), 1, 1);
        glUseProgram(0);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    }
    static inline int runs = 0;

private:
    GLuint program_ = 0;
};

// Registers the toy once per process (the registry is append-only); returns its id.
BackpatchMethod toy_method() {
    static const BackpatchMethod id = [] {
        const BackpatchMethod m =
            register_backpatch_method({"toy", "x < 0 everywhere (a test's toy)", toy_kernel, nullptr, false});
        register_backpatch_pass(
            m, [](PassContext&) -> std::unique_ptr<BackpatchPass> { return std::make_unique<ToyPass>(); });
        return m;
    }();
    return id;
}

std::vector<std::uint8_t> cpu_decisions(const std::vector<BezierPatch>& patches) {
    const PatchBatch batch = make_batch(patches);
    std::vector<std::uint8_t> culled(patches.size());
    cull_backpatch(toy_method(), batch.view(), CullView{}, BackpatchOptions{}, culled.data());
    return culled;
}

TEST(ToyBackpatchMethod, TheRegistryListsIt) {
    const BackpatchMethod id = toy_method();
    BackpatchMethod parsed = BackpatchMethod::tcone;
    ASSERT_TRUE(parse_backpatch_method("toy", parsed));
    EXPECT_EQ(parsed, id);
    EXPECT_STREQ(backpatch_method_name(id), "toy");
    const std::vector<BackpatchMethod> gpu = gpu_backpatch_methods();  // render/view --backpatch, viewer, demo
    EXPECT_NE(std::find(gpu.begin(), gpu.end(), id), gpu.end());
    const std::vector<std::string> cpu = cull_method_names();  // patchcull cull --methods
    EXPECT_NE(std::find(cpu.begin(), cpu.end(), "toy"), cpu.end());
    EXPECT_THROW(register_backpatch_method({"toy", "", toy_kernel}), Error);
    EXPECT_THROW(register_backpatch_method({"nokernel", "", nullptr}), Error);
}

TEST(ToyBackpatchMethod, TheEvaluationRunsIt) {
    toy_method();
    PatchFrame frame;
    frame.patches = test::split_teapot(1);
    frame.info.resize(frame.patches.size());  // default PatchInfo: no tangents, default texcoords
    CullEvalOptions options;
    options.views = 8;
    options.ground_truth_grid = 3;
    options.methods = {"toy", "tcone"};
    const CullEvalResult result = evaluate_cull(frame, nullptr, options);
    ASSERT_EQ(result.methods.size(), 2u);
    EXPECT_EQ(result.methods[0].name, "toy");
    // The toy ignores the view: every view culls the same patches.
    const std::vector<std::uint8_t> culled = cpu_decisions(frame.patches);
    const auto per_view = static_cast<std::uint64_t>(std::count(culled.begin(), culled.end(), 1));
    ASSERT_GT(per_view, 0u);
    EXPECT_EQ(result.methods[0].culled, per_view * static_cast<std::uint64_t>(options.views));
}

TEST(ToyBackpatchMethod, BackpatchCullerAndThePipelineRunItsPass) {
    const std::vector<BezierPatch> patches = test::split_teapot(1);
    const std::vector<std::uint8_t> expected = cpu_decisions(patches);
    const auto expected_count = static_cast<std::size_t>(std::count(expected.begin(), expected.end(), 1));

    BackpatchCuller culler(test::context());
    culler.set_patches(patches);
    std::vector<std::uint8_t> gpu;
    culler.cull(toy_method(), CullView{}, BackpatchOptions{}, &gpu);
    EXPECT_EQ(gpu, expected);

    CullPipeline pipeline(test::context());
    pipeline.set_patches(patches);
    PipelineParams params;
    params.frame.cull = CullMode::backpatch;
    params.frame.render.view = look_at({0, 1, 6}, {0, 0.5f, 0}, {0, 1, 0});
    params.frame.render.projection = perspective(0.8f, 1.0f, 0.1f, 100.0f);
    params.frame.render.width = 64;
    params.frame.render.height = 64;
    params.backpatch = toy_method();
    params.fused_pass = true;  // the toy is not fusable: its own pass runs
    const int runs_before = ToyPass::runs;
    const FrameStats stats = pipeline.render_frame(params);
    EXPECT_GT(ToyPass::runs, runs_before);
    EXPECT_FALSE(stats.fused_pass);
    EXPECT_EQ(stats.backpatch_culled, expected_count);
}

}  // namespace
}  // namespace patchcull::gl
