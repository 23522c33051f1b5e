#!/usr/bin/env bash
# README command 2: runs every test. Installs the Debian packages if missing, builds the core
# tests with AddressSanitizer + UndefinedBehaviorSanitizer and runs them, runs a short fuzz
# campaign over the input loaders (scripts/fuzz.sh, clang), then builds everything in Release with
# warnings as errors (PATCHCULL_WERROR) and runs the whole suite, two tests at a time (ctest's
# summary line comes last). The sanitizer build compiles the SIMD kernels for the wide targets only
# (AVX2, AVX-512 and the portable one; the Release build has all five): their tails are where a
# stray load would be.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="$(nproc)"

./scripts/install-deps.sh

echo "== core tests under ASan + UBSan =="
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DPATCHCULL_SANITIZE=ON -DPATCHCULL_BUILD_BENCHMARKS=OFF \
  "-DCMAKE_CXX_FLAGS=-DHWY_DISABLED_TARGETS=(HWY_SSSE3|HWY_SSE4)" >/dev/null
cmake --build build-asan -j"$JOBS" --target patchcull_core_tests patchcull_cli patchcull_cli_tests
ASAN_OPTIONS=detect_leaks=1 ctest --test-dir build-asan -j"$JOBS" -L "core|cli" --output-on-failure

echo "== fuzz campaign (libFuzzer, clang: OBJ reader and PNG loader, 20 s each) =="
./scripts/fuzz.sh 20

echo "== full suite (Release) =="
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPATCHCULL_WERROR=ON >/dev/null
cmake --build build -j"$JOBS"
ctest --test-dir build -j"$JOBS" --output-on-failure
