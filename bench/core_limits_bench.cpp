// What one core can issue, for the kernels' instruction-count limits (docs/PERFORMANCE.md,
// "Against each kernel's limit"): the throughput of 256-bit square roots, divisions and loads, and
// the cost of a mispredicted branch. Every rate is over CPU time (robust to sharing the core);
// divide cpu_clock's GHz (frustum_bench.cpp) by a row's rate for cycles per operation.
//
// core_limits/sqrt_ymm, div_ymm: 16 independent vsqrtps / vdivps on ymm registers per block
//   (inputs 2.7 and 3.1), G operations/s.
// core_limits/load_ymm, broadcast_ymm: 16 independent 32-byte vmovaps / 4-byte vbroadcastss
//   loads from one L1-resident cache line pair per block, G loads/s.
// core_limits/branch/{predictable,random}: one conditional branch per byte over 64 KiB of bytes,
//   all zero or random bits (mt19937); G bytes/s. The penalty of a mispredict is
//   2 * (cycles per byte random - cycles per byte predictable): a random bit is mispredicted half
//   the time.
// Run:
//   build/bench/patchcull_bench --benchmark_filter='^(cpu_clock|core_limits/)' --benchmark_repetitions=5
//       --benchmark_min_time=0.1
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

namespace {

#define PATCHCULL_X4(s) s s s s

__attribute__((target("avx2"))) void sqrt_block() {
    asm volatile(
        PATCHCULL_X4("vsqrtps %%ymm0, %%ymm1\n\tvsqrtps %%ymm0, %%ymm2\n\tvsqrtps %%ymm0, %%ymm4\n\tvsqrtps %%ymm0, "
                     "%%ymm5\n\t")::
            : "xmm1", "xmm2", "xmm4", "xmm5");
}

__attribute__((target("avx2"))) void div_block() {
    asm volatile(PATCHCULL_X4("vdivps %%ymm0, %%ymm3, %%ymm1\n\tvdivps %%ymm0, %%ymm3, %%ymm2\n\t"
                              "vdivps %%ymm0, %%ymm3, %%ymm4\n\tvdivps %%ymm0, %%ymm3, %%ymm5\n\t")::
                     : "xmm1", "xmm2", "xmm4", "xmm5");
}

__attribute__((target("avx2"))) void load_block(const float* p) {
    asm volatile(PATCHCULL_X4("vmovaps (%0), %%ymm1\n\tvmovaps 32(%0), %%ymm2\n\t"
                              "vmovaps 64(%0), %%ymm4\n\tvmovaps 96(%0), %%ymm5\n\t")::"r"(p)
                 : "xmm1", "xmm2", "xmm4", "xmm5");
}

__attribute__((target("avx2"))) void broadcast_block(const float* p) {
    asm volatile(PATCHCULL_X4("vbroadcastss (%0), %%ymm1\n\tvbroadcastss 4(%0), %%ymm2\n\t"
                              "vbroadcastss 8(%0), %%ymm4\n\tvbroadcastss 12(%0), %%ymm5\n\t")::"r"(p)
                 : "xmm1", "xmm2", "xmm4", "xmm5");
}

__attribute__((target("avx2"))) void set_inputs() {
    static const float two = 2.7f, three = 3.1f;
    asm volatile("vbroadcastss %0, %%ymm0\n\tvbroadcastss %1, %%ymm3" ::"m"(two), "m"(three) : "xmm0", "xmm3");
}

enum class Op { kSqrt, kDiv, kLoad, kBroadcast };

void bm_issue(benchmark::State& state, Op op) {
    if (!__builtin_cpu_supports("avx2")) {
        state.SkipWithError("AVX2 not supported");
        return;
    }
    alignas(64) static float line[32] = {1.0f};
    std::int64_t ops = 0;
    for (auto _ : state) {
        set_inputs();
        for (int i = 0; i < 1024; ++i) {
            switch (op) {
                case Op::kSqrt:
                    sqrt_block();
                    break;
                case Op::kDiv:
                    div_block();
                    break;
                case Op::kLoad:
                    load_block(line);
                    break;
                case Op::kBroadcast:
                    broadcast_block(line);
                    break;
            }
        }
        ops += 1024 * 16;
    }
    state.counters["Gops"] = benchmark::Counter(static_cast<double>(ops) * 1e-9, benchmark::Counter::kIsRate);
}

// One conditional branch per byte; the two arms differ so the compiler keeps the branch.
__attribute__((noinline)) std::uint64_t branch_per_byte(const std::uint8_t* a, std::size_t n) {
    std::uint64_t x = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (a[i])
            asm volatile("add $7, %0" : "+r"(x));
        else
            asm volatile("add $3, %0" : "+r"(x));
    }
    return x;
}

void bm_branch(benchmark::State& state, bool random) {
    std::vector<std::uint8_t> bytes(std::size_t{1} << 16, 0);
    if (random) {
        std::mt19937 rng(1);
        for (auto& b : bytes) b = static_cast<std::uint8_t>(rng() & 1u);
    }
    std::uint64_t sum = 0;
    for (auto _ : state) sum += branch_per_byte(bytes.data(), bytes.size());
    benchmark::DoNotOptimize(sum);
    state.counters["Gbytes"] =
        benchmark::Counter(static_cast<double>(state.iterations() * bytes.size()) * 1e-9, benchmark::Counter::kIsRate);
}

int register_all() {
    benchmark::RegisterBenchmark("core_limits/sqrt_ymm", [](benchmark::State& s) { bm_issue(s, Op::kSqrt); });
    benchmark::RegisterBenchmark("core_limits/div_ymm", [](benchmark::State& s) { bm_issue(s, Op::kDiv); });
    benchmark::RegisterBenchmark("core_limits/load_ymm", [](benchmark::State& s) { bm_issue(s, Op::kLoad); });
    benchmark::RegisterBenchmark("core_limits/broadcast_ymm", [](benchmark::State& s) { bm_issue(s, Op::kBroadcast); });
    benchmark::RegisterBenchmark("core_limits/branch/predictable", [](benchmark::State& s) { bm_branch(s, false); });
    benchmark::RegisterBenchmark("core_limits/branch/random", [](benchmark::State& s) { bm_branch(s, true); });
    return 0;
}

[[maybe_unused]] const int registered = register_all();

}  // namespace
