// Benchmarks of the compaction pass (gl::CompactPass, patchcull/gl/gl_compaction.h): the flag words
// of N patches -> the list of the survivors, the indirect command and the draw count.
//
// compaction_{atomic,scan}/N: one run over N patches with random flag words (each patch's reason
// none or one of the four with equal odds, so about 1 in 5 survives kDrawMaskUnculled), wall
// clock around run() + glFinish (the pass itself
// does not wait); the programs are compiled before the timed loop. items_per_second = patches/s.
// Counter survivors = the surviving fraction. On llvmpipe every figure includes the driver's CPU
// work of the dispatches (the scan issues three, the append two or three).
//
// compaction_{separate,fused}/N: the flag chain's last stage and the list of pass 2 (the newly
// visible) after it: CullStatusPass::end then CompactPass's atomic append (separate), against
// CullStatusPass::end with the append fused into it (fused: gl_passes.h). Flag words as the tests
// leave them (a reason as above, a random status), uploaded again before each iteration (not
// timed: the end rewrites them); wall clock around the calls + glFinish.
//
// Run (see docs/PERFORMANCE.md):
//   build/bench/patchcull_bench --benchmark_filter='compaction_' --benchmark_repetitions=3
//       --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <epoxy/gl.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "patchcull/gl/gl_compaction.h"
#include "patchcull/gl/gl_context.h"
#include "patchcull/gl/gl_passes.h"
#include "shared.h"

namespace {

using namespace patchcull;
using Clock = std::chrono::steady_clock;

struct CompactionScene {
    gl::GlContext context = gl::GlContext::create_headless();
    std::unique_ptr<gl::PassContext> passes;
    std::unique_ptr<gl::CompactPass> pass;
    GLuint flags = 0, list = 0, command = 0, draw_count = 0;
    std::size_t capacity = 0;
    double survivors = 0;

    CompactionScene() {
        context.make_current();
        passes = std::make_unique<gl::PassContext>();
        pass = std::make_unique<gl::CompactPass>(*passes);
        glCreateBuffers(1, &command);
        glNamedBufferData(command, 16, nullptr, GL_DYNAMIC_DRAW);
        glCreateBuffers(1, &draw_count);
        glNamedBufferData(draw_count, 4, nullptr, GL_DYNAMIC_DRAW);
    }

    // Fresh flags for n patches (and a list to match).
    void set_size(std::size_t n) {
        if (n == capacity) return;
        std::mt19937 rng(1);
        const std::uint32_t reasons[] = {0u, gl::shared::kCullFrustum, gl::shared::kCullBackPatch,
                                         gl::shared::kCullOcclusion, gl::shared::kCullObject};
        std::vector<std::uint32_t> words(n);
        std::size_t kept = 0;
        for (auto& w : words) {
            w = reasons[rng() % 5] | (rng() % 2 ? gl::shared::kStatusVisible : 0u);
            kept += (w & gl::shared::kDrawMaskUnculled) == gl::shared::kDrawValueUnculled;
        }
        survivors = static_cast<double>(kept) / static_cast<double>(n);
        glDeleteBuffers(1, &flags);
        glDeleteBuffers(1, &list);
        glCreateBuffers(1, &flags);
        glNamedBufferData(flags, static_cast<GLsizeiptr>(n * 4), words.data(), GL_STATIC_DRAW);
        glCreateBuffers(1, &list);
        glNamedBufferData(list, static_cast<GLsizeiptr>(n * 4), nullptr, GL_DYNAMIC_DRAW);
        capacity = n;
    }
};

CompactionScene& scene() {
    static CompactionScene s;
    return s;
}

void bm_compaction(benchmark::State& state, gl::CompactMethod method) {
    CompactionScene& s = scene();
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    s.set_size(n);
    const gl::PatchBuffers patches{0, s.flags, 0, 0, n};
    const gl::DrawListBuffers out{s.list, 0, s.command, 0, s.draw_count, 0};
    const auto once = [&] {
        s.pass->run(patches, gl::shared::kDrawMaskUnculled, gl::shared::kDrawValueUnculled, out, method);
        glFinish();
    };
    once();  // compiles the program, sizes the scan's sums
    for (auto _ : state) {
        const auto t0 = Clock::now();
        once();
        state.SetIterationTime(std::chrono::duration<double>(Clock::now() - t0).count());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(n));
    state.counters["survivors"] = s.survivors;
}

// The end's input words for n patches, and buffers for the counters.
struct EndScene {
    std::unique_ptr<gl::CullStatusPass> status;
    GLuint counters = 0;
    std::vector<std::uint32_t> words;
    void set_size(std::size_t n, gl::PassContext& passes) {
        if (!status) {
            status = std::make_unique<gl::CullStatusPass>(passes);
            glCreateBuffers(1, &counters);
            glNamedBufferData(counters, gl::shared::kCounterCount * 4, nullptr, GL_DYNAMIC_DRAW);
        }
        if (words.size() == n) return;
        std::mt19937 rng(2);
        const std::uint32_t reasons[] = {0u, gl::shared::kCullFrustum, gl::shared::kCullBackPatch,
                                         gl::shared::kCullOcclusion, gl::shared::kCullObject};
        words.resize(n);
        for (auto& w : words) w = reasons[rng() % 5] | (rng() % 2 ? gl::shared::kStatusVisible : 0u);
    }
};

void bm_end_and_list(benchmark::State& state, bool fused) {
    CompactionScene& s = scene();
    static EndScene e;
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    s.set_size(n);
    e.set_size(n, *s.passes);
    const gl::PatchBuffers patches{0, s.flags, 0, 0, n};
    const gl::DrawListBuffers out{s.list, 0, s.command, 0, s.draw_count, 0};
    const std::uint32_t mask = gl::shared::kDrawMaskSecondPass, value = gl::shared::kDrawValueSecondPass;
    const auto once = [&] {
        glNamedBufferSubData(s.flags, 0, static_cast<GLsizeiptr>(n * 4), e.words.data());
        glFinish();
        const auto t0 = Clock::now();
        if (fused) {
            e.status->end(patches, e.counters, 0, out, mask, value);
        } else {
            e.status->end(patches, e.counters, 0);
            s.pass->run(patches, mask, value, out, gl::CompactMethod::atomic_append);
        }
        glFinish();
        return std::chrono::duration<double>(Clock::now() - t0).count();
    };
    once();  // compiles the programs
    for (auto _ : state) state.SetIterationTime(once());
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(n));
}

}  // namespace

BENCHMARK_CAPTURE(bm_end_and_list, separate, false)
    ->Name("compaction_separate")
    ->Arg(8226)
    ->Arg(27420)
    ->Arg(1 << 20)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(bm_end_and_list, fused, true)
    ->Name("compaction_fused")
    ->Arg(8226)
    ->Arg(27420)
    ->Arg(1 << 20)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(bm_compaction, atomic, gl::CompactMethod::atomic_append)
    ->Name("compaction_atomic")
    ->Arg(1 << 16)
    ->Arg(1 << 20)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(bm_compaction, scan, gl::CompactMethod::prefix_scan)
    ->Name("compaction_scan")
    ->Arg(1 << 16)
    ->Arg(1 << 20)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
