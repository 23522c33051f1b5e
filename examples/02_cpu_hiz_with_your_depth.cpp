// examples/02_cpu_hiz_with_your_depth.cpp: occlusion culling on the CPU against a depth buffer
// the caller supplies (an engine's depth pre-pass, a software rasteriser's occluders, last
// frame's read-back): build the Hi-Z pyramid from it (patchcull/core/hiz.h), then test patches.
//
// The depth buffer is given in hiz.h's convention: W x H floats, depth[y * W + x], row 0 = bottom
// (what glReadPixels returns), window depth in [0, 1] (glDepthRange(0, 1)), larger = farther. The
// camera here is an OpenGL engine's: its projection maps depth to -1..1, so the kernel is told
// ClipDepth::minus_one_to_one (clip_space.h). No check can tell the conventions apart from the
// matrix, which is why the argument has no default: a wrong one culls visible patches silently.
//
// Scene: an occluder quad 5 units ahead, rasterised into the depth buffer by this program (pixel
// centres inside its screen rectangle, as GL samples them), and three instances of the Utah
// teapot's 32 patches, one batch with a model matrix each: one in front of the quad, one hidden
// behind it, one behind the quad's depth but beside it on screen.
//
// Usage: 02_cpu_hiz_with_your_depth [--size WxH] [--misdeclare-depth]
//   --size WxH          the depth buffer, each side in 64..4096 (default 320x240)
//   --misdeclare-depth  a mistake on purpose: build a zero-to-one projection (Direct3D, Vulkan)
//                       but still tell the kernel minus_one_to_one; it then reads every depth
//                       farther than it is, culls the front teapot, and the check must say so
// Checks: no patch of the front teapot is occluded; every patch of the hidden one is culled
// (occluded, or outside the frustum on a very narrow screen); SIMD equals the scalar reference;
// each culled patch's 17x17 surface samples (ground_truth.h) lie behind the depth stored at
// their pixel. Exit status 0 when all hold, 1 otherwise, 2 on bad arguments (one line).
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/error.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/teapot.h"

namespace pc = patchcull;

namespace {

bool parse_size(const std::string& text, int& w, int& h) {
    const std::size_t x = text.find('x');
    auto number = [](const std::string& t, int& out) {
        const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), out);
        return !t.empty() && t[0] != '-' && ec == std::errc() && end == t.data() + t.size() && out >= 64 && out <= 4096;
    };
    return x != std::string::npos && number(text.substr(0, x), w) && number(text.substr(x + 1), h);
}

// Window coordinates (x, y in pixels, z = depth in [0, 1]) of an object point, in double (the
// ground truth must not share the kernel's float rounding); m is a zero-to-one matrix.
struct Window {
    double x, y, z;
    bool in_front;  // w > 0: in front of the eye
};
Window to_window(const pc::Mat4& m, pc::Vec3 p, int width, int height) {
    double c[4];
    for (int r = 0; r < 4; ++r)
        c[r] = double(m.at(r, 0)) * p.x + double(m.at(r, 1)) * p.y + double(m.at(r, 2)) * p.z + double(m.at(r, 3));
    return {(c[0] / c[3] * 0.5 + 0.5) * width, (c[1] / c[3] * 0.5 + 0.5) * height, c[2] / c[3], c[3] > 0};
}

// The teapot (z up, about 6 wide) stood up (y up), scaled by 0.2 and moved to `at`.
pc::Mat4 place(pc::Vec3 at) {
    pc::Mat4 m;
    m.at(0, 0) = 0.2f;
    m.at(1, 1) = 0;
    m.at(2, 1) = -0.2f;  // y -> -z
    m.at(2, 2) = 0;
    m.at(1, 2) = 0.2f;  // z -> y
    m.at(0, 3) = at.x;
    m.at(1, 3) = at.y;
    m.at(2, 3) = at.z;
    return m;
}

int run(int width, int height, bool misdeclare) {
    // Camera at the origin looking down -z, OpenGL's -1..1 depth (unless misdeclared).
    const pc::ClipDepth convention = misdeclare ? pc::ClipDepth::zero_to_one : pc::ClipDepth::minus_one_to_one;
    const pc::ClipDepth declared = pc::ClipDepth::minus_one_to_one;  // what the kernel is told
    const pc::Mat4 view = pc::look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    const pc::Mat4 projection = pc::perspective(1.0471976f, float(width) / float(height), 0.1f, 100.0f, convention);
    const pc::Mat4 world_to_clip = projection * view;
    // The true window depths, for our rasteriser and the ground truth.
    const pc::Mat4 world_to_window_depth = pc::to_zero_to_one(world_to_clip, convention);

    // YOUR depth buffer: cleared to 1, then the quad x in [-2, 2], y in [-1.5, 1.5] at z = -5.
    // (Faces the eye: one depth over it.)
    std::vector<float> depth(std::size_t(width) * height, 1.0f);
    const Window lo = to_window(world_to_window_depth, {-2, -1.5f, -5}, width, height);
    const Window hi = to_window(world_to_window_depth, {2, 1.5f, -5}, width, height);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            if (x + 0.5 >= lo.x && x + 0.5 <= hi.x && y + 0.5 >= lo.y && y + 0.5 <= hi.y)
                depth[std::size_t(y) * width + x] = float(lo.z);

    pc::HiZPyramid hiz;  // keep it across frames: build() allocates only when the size changes
    hiz.build(depth.data(), width, height);

    const std::vector<pc::BezierPatch> teapot = pc::teapot_patches();
    const pc::PatchBatch batch = pc::make_batch(teapot);
    std::vector<std::uint8_t> decision(batch.size()), reference(batch.size());
    std::vector<pc::Vec3> samples(pc::kGroundTruthGrid * pc::kGroundTruthGrid);
    const pc::Vec2 corners[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};

    struct Instance {
        const char* name;
        pc::Vec3 at;
    };
    const Instance instances[] = {
        {"in front", {0, -0.3f, -3}}, {"hidden", {0, -0.3f, -10}}, {"beside", {6, -0.3f, -10}}};
    int failures = 0;
    auto fail = [&](const char* what, const char* message) {
        std::printf("FAILED (%s teapot): %s\n", what, message);
        ++failures;
    };
    for (const Instance& instance : instances) {
        const pc::Mat4 object_to_clip = world_to_clip * place(instance.at);
        const pc::Mat4 object_to_window_depth = world_to_window_depth * place(instance.at);
        pc::cull_occlusion_simd(batch.view(), object_to_clip, declared, hiz, decision.data());
        pc::cull_occlusion_scalar(batch.view(), object_to_clip, declared, hiz, reference.data());
        if (decision != reference) fail(instance.name, "SIMD and scalar decisions differ");

        std::size_t occluded = 0, outside = 0, wrong = 0;
        for (std::size_t i = 0; i < batch.size(); ++i) {
            outside += decision[i] == pc::kHiZFrustumCulled;
            if (decision[i] != pc::kHiZOccluded) continue;
            ++occluded;
            // Ground truth: every sample on screen must be behind the depth already at its pixel.
            pc::sample_displaced_patch(teapot[i], nullptr, corners, nullptr, pc::kGroundTruthGrid, samples.data());
            for (const pc::Vec3& p : samples) {
                const Window s = to_window(object_to_window_depth, p, width, height);
                if (!s.in_front || s.x < 0 || s.y < 0 || s.x >= width || s.y >= height) continue;
                if (!(depth[std::size_t(s.y) * width + std::size_t(s.x)] < s.z)) {
                    ++wrong;
                    break;
                }
            }
        }
        std::printf("%-8s teapot: %zu of %zu patches occluded, %zu outside the frustum; %zu false culls\n",
                    instance.name, occluded, batch.size(), outside, wrong);
        failures += int(wrong);
        const bool front = instance.at.z > -5, hidden = instance.at.x == 0 && !front;
        if (front && occluded > 0) fail(instance.name, "a patch in front of the occluder was culled");
        // (A very narrow screen puts some hidden patches outside the frustum: culled too.)
        if (hidden && occluded + outside != batch.size())
            fail(instance.name, "a patch hidden behind the occluder was kept");
    }
    std::printf(failures ? "FAILED\n" : "ok\n");
    return failures ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        int width = 320, height = 240;
        bool misdeclare = false;
        for (int i = 1; i < argc; ++i) {
            const std::string arg = argv[i];
            if (arg == "--misdeclare-depth") {
                misdeclare = true;
                continue;
            }
            if (arg != "--size")
                throw pc::Error("unknown argument " + pc::quote_input(arg) +
                                " (usage: [--size WxH] [--misdeclare-depth])");
            const std::string value = i + 1 < argc ? argv[++i] : "";
            if (!parse_size(value, width, height))
                throw pc::Error("--size: expected WIDTHxHEIGHT, each in 64..4096, got " + pc::quote_input(value));
        }
        return run(width, height, misdeclare);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", pc::printable_line(e.what()).c_str());
        return 2;
    }
}
