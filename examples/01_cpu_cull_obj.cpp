// examples/01_cpu_cull_obj.cpp: CPU frustum and back-patch culling of an OBJ model, the way an
// engine calls the kernels: load the control mesh, turn it into bicubic Bezier patches (ACC),
// pack them into a structure-of-arrays batch once, then per view run the kernels over it with
// decision buffers the caller owns (the kernels never allocate).
//
// Usage: 01_cpu_cull_obj [MODEL.obj] [--views N]
//   MODEL.obj  a Catmull-Clark control mesh (default: the shipped data/models/bigguy.obj)
//   --views N  random camera positions around and inside the model, N in 1..1000, default 8
// Prints one line per view. Every decision is checked against the ground truth of
// patchcull/core/ground_truth.h (17x17 dense samples of each culled patch, evaluated in double): a
// frustum-culled patch must have no sample in the view volume, a back-patch-culled one no sampled
// tangent plane facing the eye; and the SIMD kernels must agree with the scalar references.
// Exit status: 0 all checks passed; 1 a check failed, or a kernel culled nothing over the run
// (then the check proved nothing); 2 bad arguments or an unreadable model (one line on stderr).
#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/core/parallel.h"
#include "patchcull/core/patch.h"
#include "patchcull/import/model_loader.h"

namespace pc = patchcull;

namespace {

struct Options {
    std::string model = pc::shipped_model_path("bigguy.obj");
    int views = 8;
};

Options parse_options(int argc, char** argv) {
    Options o;
    bool have_model = false;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--views") {
            const std::string v = i + 1 < argc ? argv[++i] : "";
            const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), o.views);
            if (v.empty() || v[0] == '-' || ec != std::errc() || end != v.data() + v.size() || o.views < 1 ||
                o.views > 1000)
                throw pc::Error("--views: expected an integer in 1..1000, got " + pc::quote_input(v));
        } else if (arg.rfind("-", 0) == 0 || have_model) {
            throw pc::Error("unknown argument " + pc::quote_input(arg) + " (usage: [MODEL.obj] [--views N])");
        } else {
            o.model = arg;
            have_model = true;
        }
    }
    return o;
}

int run(const Options& options) {
    // OBJ -> Catmull-Clark control mesh -> one ACC Bezier patch per quad. load_model also orients
    // a closed mesh outward and says whether it is closed: back-patch culling is conservative
    // only for closed, outward-oriented surfaces drawn one-sided (README, "What contributes a pixel").
    const pc::LoadedModel model = pc::load_model(options.model, pc::Scheme::acc, 0);
    const std::vector<pc::BezierPatch>& patches = model.rest.patches;
    const pc::PatchBatch batch = pc::make_batch(patches);  // SoA, padded for SIMD; build once
    const std::size_t n = batch.size();
    std::printf("%s: %zu Bezier patches, %s; SIMD target %s\n", options.model.c_str(), n,
                model.closed ? "closed (back-patch culling applies)" : "open (no back-patch culling)",
                pc::simd_target_name());

    // Caller-owned decision buffers: one byte per patch, reused every view.
    std::vector<std::uint8_t> frustum(n), backpatch(n), reference(n);
    std::vector<pc::Vec3> samples(pc::kGroundTruthGrid * pc::kGroundTruthGrid);
    std::vector<pc::PlaneD> planes(samples.size());
    std::size_t frustum_total = 0, backpatch_total = 0, failures = 0;

    // Free views: the camera anywhere around or inside the model, so parts leave the view.
    pc::ViewGenerator views(pc::patch_bounds(model.rest), pc::ViewMode::free, /*seed=*/1);
    for (int v = 0; v < options.views; ++v) {
        const pc::Camera camera = views.next();
        const pc::Mat4 object_to_clip = camera.view_projection();  // model matrix = identity here
        // perspective() is zero-to-one (GL_ZERO_TO_ONE, D3D, Vulkan); an OpenGL -1..1 matrix
        // would be passed with ClipDepth::minus_one_to_one.
        const pc::FrustumPlanes frustum_planes = pc::make_frustum_planes(object_to_clip, pc::ClipDepth::zero_to_one);

        // Frustum kernel on all cores: disjoint subranges of the batch (starts multiple of 16).
        const pc::PatchBatchView all = batch.view();
        pc::parallel_for_ranges(n, 256, [&](std::size_t first, std::size_t last) {
            pc::cull_frustum_simd(all.subrange(first, last - first), nullptr, frustum_planes, frustum.data() + first);
        });
        pc::cull_frustum_scalar(all, nullptr, frustum_planes, reference.data());
        if (reference != frustum) {
            std::printf("view %d: SIMD and scalar frustum decisions differ\n", v);
            ++failures;
        }

        // Back-patch kernel: ptp (the parametric tangent plane test), for closed models only.
        std::fill(backpatch.begin(), backpatch.end(), 0);
        if (model.closed) {
            const float alpha = pc::clip_space_eye_alpha(camera.projection());
            pc::cull_ptp_simd(all, object_to_clip, alpha, pc::PtpRule::ncnt, backpatch.data());
            pc::cull_ptp_scalar(all, object_to_clip, alpha, pc::PtpRule::ncnt, reference.data());
            if (reference != backpatch) {
                std::printf("view %d: SIMD and scalar ptp decisions differ\n", v);
                ++failures;
            }
        }

        // Ground truth for every culled patch.
        std::size_t f = 0, b = 0, wrong = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (frustum[i]) {
                ++f;
                pc::sample_displaced_patch(patches[i], nullptr, model.rest.info[i].uv, nullptr, pc::kGroundTruthGrid,
                                           samples.data());
                if (pc::any_point_in_clip_volume(object_to_clip, samples.data(), samples.size())) ++wrong;
            }
            if (backpatch[i]) {
                ++b;
                pc::sample_tangent_planes(patches[i], pc::kGroundTruthGrid, planes.data());
                if (pc::any_plane_faces_eye(planes.data(), planes.size(), camera.eye)) ++wrong;
            }
        }
        std::printf("view %d: frustum culled %zu, back-patch (ptp) culled %zu of %zu patches; %zu false culls\n", v, f,
                    b, n, wrong);
        frustum_total += f;
        backpatch_total += b;
        failures += wrong;
    }
    if (frustum_total == 0 || (model.closed && backpatch_total == 0)) {
        std::printf("FAILED: a kernel culled nothing over %d views, so the check proved nothing about it\n",
                    options.views);
        return 1;
    }
    std::printf(failures ? "FAILED: %zu disagreements\n" : "ok: %zu disagreements with the ground truth\n", failures);
    return failures ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(parse_options(argc, argv));
    } catch (const std::exception& e) {  // patchcull::Error: "file:line: ...", "--views: ..."
        std::fprintf(stderr, "%s\n", pc::printable_line(e.what()).c_str());
        return 2;
    }
}
