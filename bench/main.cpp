// Entry point of patchcull_bench: every bench/*.cpp registers its benchmarks; this runs them.
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
