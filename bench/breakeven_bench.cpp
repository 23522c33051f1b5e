// Break-even cull rate of displaced-patch culling on our GPU pipeline (Niessner & Loop §6.3):
//   x = (RT0 + CT) / (RT - RT0)
// RT: the frame with every patch drawn; RT0: the same frame with every patch culled (issued to the
// TCS, tessellation level 0: the pipeline's fixed cost); CT: the cull pass of a displaced bound
// (gl::DisplacedCuller, CAF with the given cone, frustum + Hi-Z occlusion; the Hi-Z build itself,
// a few ms at this size, is docs/PERFORMANCE.md's Hi-Z table). Culling pays off when it culls
// more than the fraction x of the patches.
//
// Scene: MonsterFrog split once (5168 patches), procedural displacement (2% of the diagonal), one
// whole-object view, 512x512, uniform tessellation level L. Times are wall clock around glFinish
// (llvmpipe's GL_TIME_ELAPSED measures only the vertex/tessellation stage, not rasterization), so every figure
// includes the driver's CPU work; the counters are per-iteration means.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/frustum.h"
#include "patchcull/gl/gl_displaced.h"
#include "patchcull/gl/gl_renderer.h"
#include "patchcull/import/model_loader.h"

namespace {

using namespace patchcull;
using Clock = std::chrono::steady_clock;

struct BreakEvenScene {
    gl::GlContext context = gl::GlContext::create_headless();
    LoadedModel model = load_model(shipped_model_path("monsterfrog.obj"), Scheme::acc, 1);
    DisplacementMap map;
    std::vector<DisplacementRange> ranges;
    std::unique_ptr<gl::PatchRenderer> renderer;
    std::unique_ptr<gl::DisplacedCuller> culler;
    Camera camera;
    HiZPyramid hiz;

    BreakEvenScene() {
        const Bounds b = patch_bounds(model.rest);
        map = make_procedural_displacement(512, 0.02f * length(b.max - b.min));
        ranges = displacement_ranges(model.rest, &map);
        gl::PatchAttributes attributes;
        for (std::size_t p = 0; p < model.rest.patches.size(); ++p) {
            attributes.max_displacement.push_back(ranges[p].max_abs());
            const PatchInfo& info = model.rest.info[p];
            attributes.texcoords.push_back({info.uv[0], info.uv[1], info.uv[2], info.uv[3]});
        }
        renderer = std::make_unique<gl::PatchRenderer>(context);
        renderer->set_patches(model.rest.patches, attributes);
        renderer->set_displacement_map(map);
        camera = ViewGenerator(b, ViewMode::contain, 1).next();
        // The Hi-Z of the unculled frame (the pipeline's converged state on a static view).
        const gl::RenderParams params = render_params(8, false);
        renderer->render(params);
        std::vector<float> depth = renderer->read_depth();  // top row first; hiz.h wants bottom first
        for (int y = 0; y < params.height / 2; ++y)
            std::swap_ranges(depth.begin() + y * params.width, depth.begin() + (y + 1) * params.width,
                             depth.begin() + (params.height - 1 - y) * params.width);
        hiz.build(depth.data(), params.width, params.height);
        culler = std::make_unique<gl::DisplacedCuller>(context);
        culler->set_patches(model.rest.patches, ranges);
        culler->set_hiz(hiz);
    }

    gl::RenderParams render_params(int level, bool use_cull_flags) const {
        gl::RenderParams p;
        p.view = camera.view();
        p.projection = camera.projection();
        p.width = p.height = 512;
        p.tess_level = level;
        p.use_cull_flags = use_cull_flags;
        return p;
    }
};

BreakEvenScene& scene() {
    static BreakEvenScene s;
    return s;
}

double ms_of(const std::function<void()>& work, const gl::PatchRenderer& renderer) {
    renderer.finish();
    const auto start = Clock::now();
    work();
    renderer.finish();
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

void BM_break_even(benchmark::State& state) {
    BreakEvenScene& s = scene();
    const int level = static_cast<int>(state.range(0));
    const auto cone = static_cast<NormalConeKind>(state.range(1));
    const DisplacedCullView view =
        make_displaced_cull_view(s.camera.view(), s.camera.projection(), ClipDepth::zero_to_one);
    // Every patch culled (RT0: the draw issues every patch and the TCS discards each).
    const std::vector<std::uint8_t> all_culled(s.renderer->patch_count(), 1);
    // Warm-up outside the timing: shader compilation (seconds for con on llvmpipe) and first use.
    s.culler->cull_occlusion(DisplacedBoundKind::caf, cone, view);
    s.renderer->render(s.render_params(level, false));
    double rt = 0, rt0 = 0, ct = 0;
    for (auto _ : state) {
        rt += ms_of([&] { s.renderer->render(s.render_params(level, false)); }, *s.renderer);
        s.renderer->set_cull_flags(all_culled.data());
        rt0 += ms_of([&] { s.renderer->render(s.render_params(level, true)); }, *s.renderer);
        ct += ms_of([&] { s.culler->cull_occlusion(DisplacedBoundKind::caf, cone, view); }, *s.renderer);
    }
    const double n = static_cast<double>(state.iterations());
    state.counters["RT_ms"] = rt / n;
    state.counters["RT0_ms"] = rt0 / n;
    state.counters["CT_ms"] = ct / n;
    state.counters["break_even"] = (rt0 + ct) / (rt - rt0);
    state.SetLabel(std::string("caf/") + normal_cone_name(cone) + ", 5168 patches, 512x512");
}

}  // namespace

BENCHMARK(BM_break_even)
    ->ArgsProduct({{2, 4, 8, 16},
                   {static_cast<int>(NormalConeKind::full), static_cast<int>(NormalConeKind::acon),
                    static_cast<int>(NormalConeKind::con)}})
    ->ArgNames({"tess", "cone"})
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);
