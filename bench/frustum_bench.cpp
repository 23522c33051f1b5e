// Benchmarks of the view-frustum kernels (patchcull/core/frustum.h): frustum and frustum-disp, scalar
// reference vs SIMD (dispatched target), one thread vs all threads (parallel_for_ranges, grain
// 1024), on random patches around a view. items_per_second is patches per second.
//
// stream_read/* is the memory roof for the same batch sizes: it reads n * 256 bytes (the bytes the
// frustum kernel reads for n patches) with 32-byte loads and an OR reduction, so its
// items_per_second is the patches/s a purely bandwidth-bound kernel could reach.
//
// Run (see docs/PERFORMANCE.md):
//   build-simd/bench/patchcull_bench --benchmark_filter='frustum|stream'
//       --benchmark_repetitions=3 --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <hwy/targets.h>
#include <immintrin.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "cull_bench_loop.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/parallel.h"
#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

constexpr std::size_t kBytesPerPatch = 16 * 4 * sizeof(float);  // 256

struct Workload {
    PatchBatch batch;
    std::vector<float> disp;
    Mat4 object_to_clip;
    FrustumPlanes planes;
    std::vector<std::uint8_t> culled;
};

// n random bicubic patches (curved 4x4 sheets, 0.2..1.0 across) with centres uniform in a box
// around a perspective view; about half are outside the frustum. Displacement bound 0..0.1.
// rational: weights in 0.5..2 (the frustum-disp kernel then divides instead of taking its
// polynomial fast path).
Workload& workload(std::size_t n, bool rational) {
    static std::map<std::pair<std::size_t, bool>, std::unique_ptr<Workload>> cache;
    auto& slot = cache[{n, rational}];
    if (slot) return *slot;
    slot = std::make_unique<Workload>();
    Workload& w = *slot;
    std::mt19937 rng(static_cast<unsigned>(n) * 2 + rational);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    std::vector<BezierPatch> patches(n);
    w.disp.resize(n);
    for (std::size_t p = 0; p < n; ++p) {
        const Vec3 c{30 * u(rng), 12 * u(rng), 30 * u(rng) - 10};
        const float size = 0.2f + 0.8f * unit(rng);
        const Vec3 a = Vec3{u(rng), u(rng), u(rng)} * size, b = Vec3{u(rng), u(rng), u(rng)} * size;
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const Vec3 pt = c + a * (i / 3.0f - 0.5f) + b * (j / 3.0f - 0.5f) + Vec3{0, 0.2f * size * u(rng), 0};
                patches[p].cp[4 * j + i] = homogeneous(pt, rational ? 0.5f + 1.5f * unit(rng) : 1.0f);
            }
        w.disp[p] = 0.1f * unit(rng);
    }
    w.batch = make_batch(patches);
    w.object_to_clip =
        perspective(60.0f * 3.14159265f / 180, 16.0f / 9.0f, 0.1f, 200.0f) * look_at({0, 3, 15}, {0, 0, 0}, {0, 1, 0});
    w.planes = make_frustum_planes(w.object_to_clip, ClipDepth::zero_to_one);
    w.culled.assign(n, 0);
    return w;
}

enum class Kernel { kFrustum, kFrustumDisp };
enum class Impl { kScalar, kSimd };

void run_range(const Workload& w, Kernel k, Impl impl, std::size_t first, std::size_t last, std::uint8_t* culled) {
    const PatchBatchView v = w.batch.view().subrange(first, last - first);
    const float* d = w.disp.data() + first;
    std::uint8_t* out = culled + first;
    if (k == Kernel::kFrustum) {
        (impl == Impl::kSimd ? cull_frustum_simd : cull_frustum_scalar)(v, d, w.planes, out);
    } else {
        (impl == Impl::kSimd ? cull_frustum_disp_simd : cull_frustum_disp_scalar)(v, d, w.object_to_clip,
                                                                                  ClipDepth::zero_to_one, out);
    }
}

// forced_target: 0 = normal dispatch, else a Highway target bit (e.g. HWY_AVX2) to compare widths.
void bm_cull(benchmark::State& state, Kernel k, Impl impl, bool all_threads, bool rational,
             std::int64_t forced_target = 0) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    Workload& w = workload(n, rational);
    std::uint8_t* culled = w.culled.data();
    bench::run_cull_benchmark(
        state, n, culled, all_threads, forced_target,
        [&](std::size_t a, std::size_t b) { run_range(w, k, impl, a, b, culled); },
        [&] { return impl == Impl::kSimd ? simd_target_name() : "scalar"; });
}

// ---- memory roof -------------------------------------------------------------------------------

__attribute__((target("avx2"))) std::uint64_t or_reduce_avx2(const float* p, std::size_t n_floats) {
    __m256i a0 = _mm256_setzero_si256(), a1 = a0, a2 = a0, a3 = a0;
    std::size_t i = 0;
    for (; i + 32 <= n_floats; i += 32) {
        a0 = _mm256_or_si256(a0, _mm256_load_si256(reinterpret_cast<const __m256i*>(p + i)));
        a1 = _mm256_or_si256(a1, _mm256_load_si256(reinterpret_cast<const __m256i*>(p + i + 8)));
        a2 = _mm256_or_si256(a2, _mm256_load_si256(reinterpret_cast<const __m256i*>(p + i + 16)));
        a3 = _mm256_or_si256(a3, _mm256_load_si256(reinterpret_cast<const __m256i*>(p + i + 24)));
    }
    const __m256i a = _mm256_or_si256(_mm256_or_si256(a0, a1), _mm256_or_si256(a2, a3));
    alignas(32) std::uint64_t lanes[4];
    _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), a);
    std::uint64_t r = lanes[0] | lanes[1] | lanes[2] | lanes[3];
    for (; i < n_floats; ++i) {
        std::uint32_t bits;
        std::memcpy(&bits, p + i, 4);
        r |= bits;
    }
    return r;
}

std::uint64_t or_reduce(const float* p, std::size_t n_floats) {
    if (__builtin_cpu_supports("avx2")) return or_reduce_avx2(p, n_floats);
    std::uint64_t r = 0;
    for (std::size_t i = 0; i < n_floats; ++i) {
        std::uint32_t bits;
        std::memcpy(&bits, p + i, 4);
        r |= bits;
    }
    return r;
}

void bm_stream(benchmark::State& state, bool all_threads) {
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    const std::size_t floats_per_patch = kBytesPerPatch / sizeof(float);
    static std::map<std::size_t, std::unique_ptr<PatchBatch>> buffers;  // 64-byte aligned storage
    auto& buf = buffers[n];
    if (!buf) {
        buf = std::make_unique<PatchBatch>(n);  // n patches: exactly 64 * stride floats
        for (int k = 0; k < 16; ++k)
            for (int c = 0; c < 4; ++c) std::memset(buf->component(k, c), 1, buf->stride() * sizeof(float));
    }
    const float* data = buf->component(0, 0);
    const std::size_t total = buf->stride() * floats_per_patch;
    for (auto _ : state) {
        std::uint64_t r = 0;
        if (all_threads) {
            // Same split as the kernels: grain 1024 patches -> chunks of 1024 * 64 floats.
            const std::size_t chunk = bench::kBenchGrain * floats_per_patch;
            std::vector<std::uint64_t> part((total + chunk - 1) / chunk, 0);
            parallel_for_ranges(part.size(), 1, [&](std::size_t a, std::size_t b) {
                for (std::size_t c = a; c < b; ++c) {
                    const std::size_t first = c * chunk, len = std::min(chunk, total - first);
                    part[c] = or_reduce(data + first, len);
                }
            });
            for (std::uint64_t v : part) r |= v;
        } else {
            r = or_reduce(data, total);
        }
        benchmark::DoNotOptimize(r);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * total * sizeof(float)));
}

// Core clock: a chain of dependent integer multiplies (3 cycles latency on every Intel core since
// Sandy Bridge), 64 per block; cycles/s = 3 * multiplies/s. (perf has no cycle counter in this VM
// and lscpu reports no MHz; a chain of `add $1` is no good: Golden Cove folds those at rename.)
void bm_clock(benchmark::State& state) {
    std::uint64_t x = 0;
    std::int64_t adds = 0;
    for (auto _ : state) {
        for (int i = 0; i < 1024; ++i) {
            asm volatile(
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                "imul $3, %0\n\timul $3, %0\n\timul $3, %0\n\timul $3, %0\n\t"
                : "+r"(x));
        }
        adds += 3 * 1024 * 64;
    }
    benchmark::DoNotOptimize(x);
    state.counters["GHz"] = benchmark::Counter(static_cast<double>(adds) * 1e-9, benchmark::Counter::kIsRate);
}

// FP peak: 12 independent FMA chains (4-cycle latency, 2 pipes: 8 in flight suffice), lanes * 2
// flops per FMA. Reported as G vector-FMA/s and GFLOP/s over CPU time.
template <int kLanes>
__attribute__((target("avx2,fma,avx512f"))) void fma_chains(std::int64_t iters, float* sink) {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wignored-attributes"  // vector types as template arguments
    std::conditional_t<kLanes == 16, __m512, __m256> a[12];
#pragma GCC diagnostic pop
    for (int i = 0; i < 12; ++i) {
        if constexpr (kLanes == 16)
            a[i] = _mm512_set1_ps(1.0f + i * 1e-3f);
        else
            a[i] = _mm256_set1_ps(1.0f + i * 1e-3f);
    }
    for (std::int64_t k = 0; k < iters; ++k) {
#pragma GCC unroll 12
        for (int i = 0; i < 12; ++i) {
            if constexpr (kLanes == 16)
                a[i] = _mm512_fmadd_ps(a[i], _mm512_set1_ps(0.999999f), _mm512_set1_ps(1e-7f));
            else
                a[i] = _mm256_fmadd_ps(a[i], _mm256_set1_ps(0.999999f), _mm256_set1_ps(1e-7f));
        }
    }
    for (int i = 0; i < 12; ++i) {  // every chain is live: sink holds 12 * 16 floats
        if constexpr (kLanes == 16)
            _mm512_storeu_ps(sink + 16 * i, a[i]);
        else
            _mm256_storeu_ps(sink + 16 * i, a[i]);
    }
}

template <int kLanes>
void bm_fma_peak(benchmark::State& state) {
    if (!__builtin_cpu_supports("fma") || (kLanes == 16 && !__builtin_cpu_supports("avx512f"))) {
        state.SkipWithError("ISA not supported");
        return;
    }
    alignas(64) float sink[12 * 16];
    constexpr std::int64_t kIters = 4096;
    for (auto _ : state) {
        fma_chains<kLanes>(kIters, sink);
        benchmark::DoNotOptimize(sink);
    }
    const double fmas = static_cast<double>(state.iterations()) * kIters * 12;
    state.counters["G_vector_FMA"] = benchmark::Counter(fmas * 1e-9, benchmark::Counter::kIsRate);
    state.counters["GFLOPs"] = benchmark::Counter(fmas * 2 * kLanes * 1e-9, benchmark::Counter::kIsRate);
}

const std::vector<std::int64_t> kSizes = {1450, 5168, 65536};
constexpr std::int64_t kL1Size = 128;        // 32 KiB of control points: fits the 48 KiB L1
constexpr std::int64_t kDramSize = 1 << 20;  // 256 MiB of control points: far beyond the caches

int register_all() {
    for (Kernel k : {Kernel::kFrustum, Kernel::kFrustumDisp}) {
        const std::string kname = k == Kernel::kFrustum ? "frustum" : "frustum_disp";
        for (Impl impl : {Impl::kScalar, Impl::kSimd})
            for (bool mt : {false, true}) {
                const std::string name =
                    kname + "/" + (impl == Impl::kSimd ? "simd" : "scalar") + "/" + (mt ? "all_threads" : "1_thread");
                auto* b = benchmark::RegisterBenchmark(name.c_str(),
                                                       [=](benchmark::State& s) { bm_cull(s, k, impl, mt, false); });
                for (std::int64_t n : kSizes) b->Arg(n);
                if (impl == Impl::kSimd) b->Arg(kL1Size)->Arg(kDramSize);
                b->UseRealTime()->Unit(benchmark::kMicrosecond);
            }
        // The same SIMD kernel forced to 8-lane AVX2 (the dispatched target here is AVX3, 16 lanes).
        {
            auto* b = benchmark::RegisterBenchmark((kname + "/simd_avx2/1_thread").c_str(), [=](benchmark::State& s) {
                bm_cull(s, k, Impl::kSimd, false, false, HWY_AVX2);
            });
            for (std::int64_t n : kSizes) b->Arg(n);
            b->UseRealTime()->Unit(benchmark::kMicrosecond);
        }
        // Rational weights (frustum-disp divides; frustum does the same work as for polynomials).
        for (Impl impl : {Impl::kScalar, Impl::kSimd}) {
            const std::string name = kname + "_rational/" + (impl == Impl::kSimd ? "simd" : "scalar") + "/1_thread";
            benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& s) { bm_cull(s, k, impl, false, true); })
                ->Arg(5168)
                ->UseRealTime()
                ->Unit(benchmark::kMicrosecond);
        }
    }
    for (bool mt : {false, true}) {
        auto* b = benchmark::RegisterBenchmark(mt ? "stream_read/all_threads" : "stream_read/1_thread",
                                               [=](benchmark::State& s) { bm_stream(s, mt); });
        b->Arg(kL1Size);
        for (std::int64_t n : kSizes) b->Arg(n);
        b->Arg(kDramSize)->UseRealTime()->Unit(benchmark::kMicrosecond);
    }
    benchmark::RegisterBenchmark("fma_peak/avx512", bm_fma_peak<16>);
    benchmark::RegisterBenchmark("fma_peak/avx2", bm_fma_peak<8>);
    benchmark::RegisterBenchmark("cpu_clock", bm_clock);  // rate over CPU time: robust to sharing the core
    return 0;
}

[[maybe_unused]] const int registered = register_all();

}  // namespace
