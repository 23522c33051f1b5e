// The main job (`patchcull` with no arguments, or `patchcull demo`): the built-in default scene.
// Until the GL pipeline is wired into the CLI (issue 4) it runs the CPU cull pipeline on the default scene:
// BigGuy and MonsterFrog (ACC patches, procedural displacement), animated over a few frames,
// each frame seen from random cameras, every decision checked against the dense-sample ground
// truth. It prints the culling summary.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>

#include "commands.h"
#include "patchcull/animation.h"
#include "patchcull/cull_eval.h"
#include "patchcull/frustum.h"
#include "patchcull/parallel.h"

namespace patchcull::cli {

namespace {

struct Pass {
    const char* label;
    ViewMode mode;
    bool displaced;
    std::vector<std::string> methods;
};

}  // namespace

int run_demo() {
    constexpr int kFrames = 6;
    constexpr int kViewsPerFrame = 40;
    // View-frustum culling of the displaced surface from free-roaming cameras; back-patch culling
    // (which does not bound displacement, seed 001 §8) of the undisplaced surface from cameras
    // that see the whole character.
    const Pass passes[] = {
        {"free views, displaced", ViewMode::free, true, {"frustum", "frustum-disp"}},
        {"contain views", ViewMode::contain, false, {"tcone", "ncone", "ptp", "ptp-pcnt"}},
    };
    const auto start = std::chrono::steady_clock::now();
    std::printf("patchcull default scene: BigGuy + MonsterFrog, ACC patches, procedural displacement,\n"
                "%d animated frames x %d random views per pass; CPU kernels (%s, %d threads).\n\n",
                kFrames, kViewsPerFrame, simd_target_name(), hardware_threads());
    std::printf("%-16s %-22s %-12s %8s %10s %12s %10s\n", "model", "pass", "method", "patches", "cull rate",
                "false culls", "ns/patch");
    std::uint64_t total_false = 0;
    for (const char* file : {"bigguy.obj", "monsterfrog.obj"}) {
        const LoadedModel model = load_model(shipped_model_path(file), Scheme::acc, 0);
        const Bounds rest_bounds = patch_bounds(model.rest);
        const DisplacementMap displacement =
            make_procedural_displacement(512, 0.02f * length(rest_bounds.max - rest_bounds.min));
        std::vector<Vec3> positions;
        PatchFrame frame;
        for (const Pass& pass : passes) {
            std::map<std::string, CullMethodResult> sums;
            for (int f = 0; f < kFrames; ++f) {
                animate(model.subdiv->mesh.positions, f / 24.0f * 4.0f, AnimationParams{}, positions);
                evaluate_frame(model, positions, frame);
                CullEvalOptions options;
                options.views = kViewsPerFrame;
                options.seed = 1000 + f;
                options.mode = pass.mode;
                options.methods = pass.methods;
                const CullEvalResult r = evaluate_cull(frame, pass.displaced ? &displacement : nullptr, options);
                for (const CullMethodResult& m : r.methods) {
                    CullMethodResult& s = sums[m.name];
                    s.culled += m.culled;
                    s.false_culls += m.false_culls;
                    s.ns_per_patch += m.ns_per_patch / kFrames;
                }
            }
            const double pairs = double(model.rest.patches.size()) * kFrames * kViewsPerFrame;
            for (const std::string& name : pass.methods) {
                const CullMethodResult& s = sums[name];
                total_false += s.false_culls;
                std::printf("%-16s %-22s %-12s %8zu %9.1f%% %12llu %10.2f\n", file, pass.label, name.c_str(),
                            model.rest.patches.size(), 100.0 * s.culled / pairs,
                            static_cast<unsigned long long>(s.false_culls), s.ns_per_patch);
            }
        }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("\nfalse culls in total: %llu (must be 0); %.1f s\n", static_cast<unsigned long long>(total_false),
                seconds);
    std::printf("The OpenGL pipeline (library patchcull_gl, tests/gl) is not yet wired into this job: rendering\n"
                "out/frame.png and out/cull.png is still to come (issue 4).\n");
    return total_false == 0 ? 0 : 1;
}

Runner add_demo_command(CLI::App& app) {
    app.add_subcommand("demo", "Run the main job on the built-in default scene (the default command)");
    return run_demo;
}

}  // namespace patchcull::cli
