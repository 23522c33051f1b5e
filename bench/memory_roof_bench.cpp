// Batches at the memory roof: the stream-read roof and the SIMD cull kernels on the
// plain, plain + software prefetch and blocked layouts (patchcull/core/patch.h), at the working sets of
// 1450, 5168, 65536 and 1M patches (256 bytes each: 0.37 MB, 1.3 MB, 16.8 MB, 268 MB), on one
// thread and on all threads (parallel_for_ranges, grain 1024 patches, as cull_bench_loop.h).
// bytes_per_second is the control-point bytes the kernel reads (256 per patch), so a row's ratio
// to the roof row of the same size and thread count is its share of the memory roof.
//
// roof/sum/{1_thread,all_threads}/N: sum of N * 64 floats (the bytes of N patches) with 64-byte
//   loads into 8 independent accumulators (AVX-512, else AVX2, else scalar); all_threads splits
//   the array into the same 1024-patch chunks the kernels get.
// layout/<kernel>/<plain|plain_prefetch|blocked|blocked_prefetch>/<1_thread|all_threads>/N: kernel
//   in frustum, tcone, occlusion (Hi-Z, 1920x1080 synthetic pyramid) and fused (cull_fused_simd,
//   plan frustum -> tcone -> Hi-Z); the _prefetch rows set
//   the default distances (patch.h), the others 0. Only kernels that prefetch (frustum) differ.
// scaling/<kernel>/<1_thread|all_threads>/N: plain layout, N = 256 .. 65536, all_threads with one
//   range per thread (scripts/kernel_scaling.sh prints the speedup table).
// layout_prefetch/frustum/<plain|blocked>/N/D: prefetch distance D patches (0 = off), one
//   thread: the sweep that chose the default distances.
// entry/<kernel>/<plain|blocked>/<1_thread|all_threads>/N: the parallel entries (parallel_cull.h)
//   at 1450, 65536 and 1M patches, default prefetching, in a oneTBB arena of one thread or of all.
// entry_avx2/<kernel>/plain/<1_thread|all_threads>/N: the same with Highway forced to AVX2 (skipped
//   without it): on an AVX-512 machine, the code valgrind runs and counts (it has no AVX-512). Also
//   at N = 65552 and 1M + 16, whose plain component arrays are not a multiple of 4 KiB apart (at
//   65536 and 1M they are, and share one L1 set).
//
// Run (docs/PERFORMANCE.md, "Batches at the memory roof"):
//   build/bench/patchcull_bench --benchmark_filter='^(roof|layout)/' --benchmark_repetitions=3
//       --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <hwy/targets.h>
#include <immintrin.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "cull_bench_loop.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/parallel.h"
#include "patchcull/core/parallel_cull.h"
#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

constexpr std::size_t kBytesPerPatch = 4 * kPatchPoints * sizeof(float);  // 256
const std::vector<std::int64_t> kSizes = {1450, 5168, 65536, 1 << 20};

// ---- the roof ----------------------------------------------------------------------------------

__attribute__((target("avx512f"))) float sum_avx512(const float* p, std::size_t n) {
    __m512 a[8];
    for (auto& v : a) v = _mm512_setzero_ps();
    std::size_t i = 0;
    for (; i + 128 <= n; i += 128)
        for (int k = 0; k < 8; ++k) a[k] = _mm512_add_ps(a[k], _mm512_load_ps(p + i + 16 * k));
    for (int k = 1; k < 8; ++k) a[0] = _mm512_add_ps(a[0], a[k]);
    // The 16 lanes summed from memory: GCC 12's _mm512_reduce_add_ps warns -Wuninitialized inside
    // its own header.
    alignas(64) float lanes[16];
    _mm512_store_ps(lanes, a[0]);
    float s = 0;
    for (float lane : lanes) s += lane;
    for (; i < n; ++i) s += p[i];
    return s;
}

__attribute__((target("avx2"))) float sum_avx2(const float* p, std::size_t n) {
    __m256 a[8];
    for (auto& v : a) v = _mm256_setzero_ps();
    std::size_t i = 0;
    for (; i + 64 <= n; i += 64)
        for (int k = 0; k < 8; ++k) a[k] = _mm256_add_ps(a[k], _mm256_load_ps(p + i + 8 * k));
    for (int k = 1; k < 8; ++k) a[0] = _mm256_add_ps(a[0], a[k]);
    alignas(32) float l[8];
    _mm256_store_ps(l, a[0]);
    float s = l[0] + l[1] + l[2] + l[3] + l[4] + l[5] + l[6] + l[7];
    for (; i < n; ++i) s += p[i];
    return s;
}

float sum_floats(const float* p, std::size_t n) {
    if (__builtin_cpu_supports("avx512f")) return sum_avx512(p, n);
    if (__builtin_cpu_supports("avx2")) return sum_avx2(p, n);
    float s[8] = {};
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8)
        for (int k = 0; k < 8; ++k) s[k] += p[i + k];
    for (; i < n; ++i) s[0] += p[i];
    return s[0] + s[1] + s[2] + s[3] + s[4] + s[5] + s[6] + s[7];
}

void bm_roof(benchmark::State& state, bool all_threads) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    static std::map<std::size_t, std::unique_ptr<detail::AlignedFloats>> buffers;
    auto& buf = buffers[n];
    if (!buf) buf = std::make_unique<detail::AlignedFloats>(n * kBytesPerPatch / sizeof(float), 1.0f);
    const float* data = buf->data();
    const std::size_t total = buf->size();
    const std::size_t chunk = bench::kBenchGrain * kBytesPerPatch / sizeof(float);
    std::vector<float> part((total + chunk - 1) / chunk);
    for (auto _ : state) {
        float r = 0;
        if (all_threads) {
            parallel_for_ranges(part.size(), 1, [&](std::size_t a, std::size_t b) {
                for (std::size_t c = a; c < b; ++c) {
                    const std::size_t first = c * chunk;
                    part[c] = sum_floats(data + first, std::min(chunk, total - first));
                }
            });
            for (float v : part) r += v;
        } else {
            r = sum_floats(data, total);
        }
        benchmark::DoNotOptimize(r);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * total * sizeof(float)));
    state.counters["threads"] = all_threads ? hardware_threads() : 1;
}

// ---- the kernels -------------------------------------------------------------------------------

// The frustum benchmark's patches (frustum_bench.cpp, hiz_bench.cpp): curved sheets 0.2..1 across,
// centres uniform in a box around a perspective view, about half outside the frustum; in both
// layouts. The Hi-Z pyramid is a 1920x1080 screen of 60 random occluder rectangles at distances
// 8..20 (as hiz_bench.cpp's).
struct Workload {
    PatchBatch plain;
    PatchBlocks blocked;
    std::vector<float> disp;
    Mat4 object_to_clip;
    FrustumPlanes planes;
    Vec3 eye{0, 3, 15};
    float alpha = 0;  // clip_space_eye_alpha of the projection (ptp)
    HiZPyramid hiz;
    FusedCullSetup fused;  // plan FBH (frustum, tcone, Hi-Z), the default FusedPlan
    CullView view;         // the same view for the parallel entries
    std::vector<std::uint8_t> culled;
};

HiZPyramid make_pyramid() {
    const int W = 1920, H = 1080;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0, 1);
    std::vector<float> depth(static_cast<std::size_t>(W) * H, 1.0f);
    const float zn = 0.1f, zf = 200.0f;
    for (int r = 0; r < 60; ++r) {
        const int x0 = static_cast<int>(unit(rng) * W), y0 = static_cast<int>(unit(rng) * H);
        const int w = 1 + static_cast<int>(unit(rng) * W * 0.3f), h = 1 + static_cast<int>(unit(rng) * H * 0.3f);
        const float z = (zf / (zf - zn)) * (1 - zn / (8 + 12 * unit(rng)));
        for (int y = y0; y < std::min(H, y0 + h); ++y)
            for (int x = x0; x < std::min(W, x0 + w); ++x)
                depth[static_cast<std::size_t>(y) * W + x] = std::min(depth[static_cast<std::size_t>(y) * W + x], z);
    }
    HiZPyramid hiz;
    hiz.build(depth.data(), W, H);
    return hiz;
}

Workload& workload(std::size_t n) {
    static std::map<std::size_t, std::unique_ptr<Workload>> cache;
    auto& slot = cache[n];
    if (slot) return *slot;
    slot = std::make_unique<Workload>();
    Workload& w = *slot;
    std::mt19937 rng(static_cast<unsigned>(n) * 2);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    w.plain = PatchBatch(n);
    w.disp.resize(n);
    for (std::size_t p = 0; p < n; ++p) {
        const Vec3 c{30 * u(rng), 12 * u(rng), 30 * u(rng) - 10};
        const float size = 0.2f + 0.8f * unit(rng);
        const Vec3 a = Vec3{u(rng), u(rng), u(rng)} * size, b = Vec3{u(rng), u(rng), u(rng)} * size;
        BezierPatch patch;
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const Vec3 pt = c + a * (i / 3.0f - 0.5f) + b * (j / 3.0f - 0.5f) + Vec3{0, 0.2f * size * u(rng), 0};
                patch.cp[4 * j + i] = homogeneous(pt, 1.0f);
            }
        w.plain.set(p, patch);
        w.disp[p] = 0.1f * unit(rng);
    }
    w.blocked = PatchBlocks(w.plain.view());
    const Mat4 proj = perspective(60.0f * 3.14159265f / 180, 16.0f / 9.0f, 0.1f, 200.0f);
    w.object_to_clip = proj * look_at(w.eye, {0, 0, 0}, {0, 1, 0});
    w.alpha = clip_space_eye_alpha(proj);
    w.planes = make_frustum_planes(w.object_to_clip, ClipDepth::zero_to_one);
    w.hiz = make_pyramid();
    w.fused = make_fused_setup(w.object_to_clip, ClipDepth::zero_to_one, w.eye, BackPatchCone::tcone, &w.hiz);
    w.view = make_cull_view(look_at(w.eye, {0, 0, 0}, {0, 1, 0}), proj, ClipDepth::zero_to_one, w.eye);
    w.culled.assign(n, 0);
    return w;
}

enum class Kernel { kFrustum, kFrustumDisp, kTcone, kNcone, kPtp, kOcclusion, kFused };
enum class Layout { kPlain, kPlainPrefetch, kBlocked, kBlockedPrefetch };

const char* kernel_name(Kernel k) {
    switch (k) {
        case Kernel::kFrustum:
            return "frustum";
        case Kernel::kFrustumDisp:
            return "frustum_disp";
        case Kernel::kTcone:
            return "tcone";
        case Kernel::kNcone:
            return "ncone";
        case Kernel::kPtp:
            return "ptp";
        case Kernel::kOcclusion:
            return "occlusion";
        default:
            return "fused";
    }
}
const char* layout_name(Layout l) {
    switch (l) {
        case Layout::kPlain:
            return "plain";
        case Layout::kPlainPrefetch:
            return "plain_prefetch";
        case Layout::kBlocked:
            return "blocked";
        default:
            return "blocked_prefetch";
    }
}

void run_kernel(const Workload& w, Kernel k, const PatchBatchView& all, std::size_t first, std::size_t last,
                std::uint8_t* culled) {
    const PatchBatchView v = all.subrange(first, last - first);
    std::uint8_t* out = culled + first;
    switch (k) {
        case Kernel::kFrustum:
            cull_frustum_simd(v, w.disp.data() + first, w.planes, out);
            break;
        case Kernel::kFrustumDisp:
            cull_frustum_disp_simd(v, w.disp.data() + first, w.object_to_clip, ClipDepth::zero_to_one, out);
            break;
        case Kernel::kTcone:
            cull_tcone_simd(v, w.eye, out);
            break;
        case Kernel::kNcone:
            cull_ncone_simd(v, w.eye, out);
            break;
        case Kernel::kPtp:
            cull_ptp_simd(v, w.object_to_clip, w.alpha, PtpRule::ncnt, out);
            break;
        case Kernel::kOcclusion:
            cull_occlusion_simd(v, w.object_to_clip, ClipDepth::zero_to_one, w.hiz, out);
            break;
        case Kernel::kFused:
            cull_fused_simd(v, w.fused, FusedPlan{}, out);
            break;
    }
}

// Sets the process-wide prefetch distances (patch.h) for one benchmark and restores them after.
struct PrefetchScope {
    std::size_t saved_plain = plain_prefetch_distance(), saved_blocked = blocked_prefetch_distance();
    PrefetchScope(std::size_t plain, std::size_t blocked) {
        set_plain_prefetch_distance(plain);
        set_blocked_prefetch_distance(blocked);
    }
    ~PrefetchScope() {
        set_plain_prefetch_distance(saved_plain);
        set_blocked_prefetch_distance(saved_blocked);
    }
};

void bm_layout(benchmark::State& state, Kernel k, Layout layout, bool all_threads) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    Workload& w = workload(n);
    const bool blocked = layout == Layout::kBlocked || layout == Layout::kBlockedPrefetch;
    const PatchBatchView all = blocked ? w.blocked.view() : w.plain.view();
    const PrefetchScope scope(layout == Layout::kPlainPrefetch ? kDefaultPlainPrefetch : 0,
                              layout == Layout::kBlockedPrefetch ? kDefaultBlockedPrefetch : 0);
    std::uint8_t* culled = w.culled.data();
    bench::run_cull_benchmark(
        state, n, culled, all_threads, 0, [&](std::size_t a, std::size_t b) { run_kernel(w, k, all, a, b, culled); },
        [&] { return simd_target_name(); });
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * kBytesPerPatch));
}

// Plain layout, one thread, or all threads with the batch split into one range per thread (a
// multiple of 16 patches each): the best case for threading small batches.
void bm_scaling(benchmark::State& state, Kernel k, bool all_threads) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    Workload& w = workload(n);
    std::uint8_t* culled = w.culled.data();
    const std::size_t threads = static_cast<std::size_t>(hardware_threads());
    const std::size_t grain = std::max<std::size_t>(16, (n + 16 * threads - 1) / (16 * threads) * 16);
    for (auto _ : state) {
        if (all_threads) {
            parallel_for_ranges(n, grain,
                                [&](std::size_t a, std::size_t b) { run_kernel(w, k, w.plain.view(), a, b, culled); });
        } else {
            run_kernel(w, k, w.plain.view(), 0, n, culled);
        }
        benchmark::DoNotOptimize(culled);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * kBytesPerPatch));
    state.counters["threads"] = all_threads ? static_cast<double>(threads) : 1.0;
    state.counters["grain"] = all_threads ? static_cast<double>(grain) : static_cast<double>(n);
}

void bm_prefetch(benchmark::State& state, Kernel k, bool blocked) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    Workload& w = workload(n);
    const std::size_t d = static_cast<std::size_t>(state.range(1));
    const PrefetchScope scope(d, d);
    std::uint8_t* culled = w.culled.data();
    const PatchBatchView all = blocked ? w.blocked.view() : w.plain.view();
    bench::run_cull_benchmark(
        state, n, culled, false, 0, [&](std::size_t a, std::size_t b) { run_kernel(w, k, all, a, b, culled); },
        [&] { return simd_target_name(); });
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * kBytesPerPatch));
}

void run_entry(const Workload& w, Kernel k, const PatchBatchView& v, std::uint8_t* out) {
    switch (k) {
        case Kernel::kFrustum:
            cull_frustum_parallel(v, w.disp.data(), w.view, out);
            break;
        case Kernel::kFrustumDisp:
            cull_frustum_disp_parallel(v, w.disp.data(), w.view, out);
            break;
        case Kernel::kTcone:
            cull_backpatch_parallel(BackpatchMethod::tcone, v, w.view, {}, out);
            break;
        case Kernel::kNcone:
            cull_backpatch_parallel(BackpatchMethod::ncone, v, w.view, {}, out);
            break;
        case Kernel::kPtp:
            cull_backpatch_parallel(BackpatchMethod::ptp, v, w.view, {}, out);
            break;
        case Kernel::kOcclusion:
            cull_occlusion_parallel(v, w.view, w.hiz, out);
            break;
        case Kernel::kFused:
            cull_fused_parallel(v, w.fused, FusedPlan{}, out);
            break;
    }
}

// A parallel entry in an arena of one thread or of every core (an engine's own arena).
// forced_target: 0 = normal dispatch, else a Highway target bit (HWY_AVX2).
void bm_entry(benchmark::State& state, Kernel k, bool blocked, bool all_threads, std::int64_t forced_target = 0) {
    if (forced_target != 0) {
        if ((hwy::SupportedTargets() & forced_target) == 0) {
            state.SkipWithError("target not supported on this CPU");
            return;
        }
        hwy::SetSupportedTargetsForTest(forced_target);
    }
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    Workload& w = workload(n);
    const PatchBatchView all = blocked ? w.blocked.view() : w.plain.view();
    tbb::task_arena arena(all_threads ? tbb::task_arena::automatic : 1);
    std::uint8_t* culled = w.culled.data();
    for (auto _ : state) {
        arena.execute([&] { run_entry(w, k, all, culled); });
        benchmark::DoNotOptimize(culled);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * kBytesPerPatch));
    state.counters["threads"] = arena.max_concurrency();
    state.SetLabel(simd_target_name());
    if (forced_target != 0) hwy::SetSupportedTargetsForTest(0);
}

int register_all() {
    for (bool mt : {false, true}) {
        auto* b = benchmark::RegisterBenchmark(mt ? "roof/sum/all_threads" : "roof/sum/1_thread",
                                               [=](benchmark::State& s) { bm_roof(s, mt); });
        for (std::int64_t n : kSizes) b->Arg(n);
        b->UseRealTime()->Unit(benchmark::kMicrosecond);
    }
    std::vector<Kernel> kernels = {Kernel::kFrustum, Kernel::kTcone, Kernel::kOcclusion, Kernel::kFused};
    for (Kernel k : kernels)
        for (Layout l : {Layout::kPlain, Layout::kPlainPrefetch, Layout::kBlocked, Layout::kBlockedPrefetch})
            for (bool mt : {false, true}) {
                const std::string name = std::string("layout/") + kernel_name(k) + "/" + layout_name(l) + "/" +
                                         (mt ? "all_threads" : "1_thread");
                auto* b =
                    benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& s) { bm_layout(s, k, l, mt); });
                for (std::int64_t n : kSizes) b->Arg(n);
                b->UseRealTime()->Unit(benchmark::kMicrosecond);
            }
    for (Kernel k : {Kernel::kFrustum, Kernel::kFrustumDisp, Kernel::kTcone, Kernel::kNcone, Kernel::kPtp,
                     Kernel::kOcclusion, Kernel::kFused})
        for (bool blocked : {false, true})
            for (bool mt : {false, true}) {
                const std::string name = std::string("entry/") + kernel_name(k) + "/" +
                                         (blocked ? "blocked" : "plain") + "/" + (mt ? "all_threads" : "1_thread");
                auto* b = benchmark::RegisterBenchmark(name.c_str(),
                                                       [=](benchmark::State& s) { bm_entry(s, k, blocked, mt); });
                for (std::int64_t n : {1450, 65536, 1 << 20}) b->Arg(n);
                b->UseRealTime()->Unit(benchmark::kMicrosecond);
            }
    for (Kernel k : {Kernel::kFrustum, Kernel::kFrustumDisp, Kernel::kTcone, Kernel::kNcone, Kernel::kPtp,
                     Kernel::kOcclusion, Kernel::kFused})
        for (bool mt : {false, true}) {
            const std::string name =
                std::string("entry_avx2/") + kernel_name(k) + "/plain/" + (mt ? "all_threads" : "1_thread");
            auto* b = benchmark::RegisterBenchmark(name.c_str(),
                                                   [=](benchmark::State& s) { bm_entry(s, k, false, mt, HWY_AVX2); });
            for (std::int64_t n : {1450, 65536, 65552, 1 << 20, (1 << 20) + 16}) b->Arg(n);
            b->UseRealTime()->Unit(benchmark::kMicrosecond);
        }
    for (Kernel k : {Kernel::kFrustum, Kernel::kFrustumDisp, Kernel::kTcone, Kernel::kNcone, Kernel::kPtp,
                     Kernel::kOcclusion, Kernel::kFused})
        for (bool mt : {false, true}) {
            const std::string name = std::string("scaling/") + kernel_name(k) + "/" + (mt ? "all_threads" : "1_thread");
            auto* b = benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& s) { bm_scaling(s, k, mt); });
            for (std::int64_t n = 256; n <= 65536; n *= 2) b->Arg(n);
            b->UseRealTime()->Unit(benchmark::kMicrosecond);
        }
    for (bool blocked : {false, true}) {
        auto* b =
            benchmark::RegisterBenchmark(blocked ? "layout_prefetch/frustum/blocked" : "layout_prefetch/frustum/plain",
                                         [=](benchmark::State& s) { bm_prefetch(s, Kernel::kFrustum, blocked); });
        for (std::int64_t n : {std::int64_t{5168}, std::int64_t{65536}, std::int64_t{1} << 20})
            for (std::int64_t d : {0, 16, 32, 64, 128, 256, 512}) b->Args({n, d});
        b->UseRealTime()->Unit(benchmark::kMicrosecond);
    }
    return 0;
}

[[maybe_unused]] const int registered = register_all();

}  // namespace
