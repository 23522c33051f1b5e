#!/usr/bin/env bash
# README command 2: runs every test. Installs the Debian packages if missing, builds the core
# tests with AddressSanitizer + UndefinedBehaviorSanitizer and runs them, runs a short fuzz
# campaign over the input loaders (scripts/fuzz.sh, clang), then builds everything in Release with
# warnings as errors (PATCHCULL_WERROR) and runs the whole suite, two tests at a time (ctest's
# summary line comes before the phases' times).
# The sanitizer tree is the kernels' (the core suite, no GL; Debug, assertions on) and compiles
# the SIMD kernels for the wide targets and the portable one only (AVX2, AVX-512, EMU128: their
# group tails are where a stray load would be); all five targets run again in the Release suite,
# the only other build of the core tests. The import, CLI, GL and tools suites are built once, in
# Release. The CPU-only package test checks the sanitizer tree (no GL, no Vulkan) rather than
# building the CPU layers again.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="$(nproc)"
phases=""
phase_start=$SECONDS
end_phase() {
  phases+="  $1: $((SECONDS - phase_start)) s"$'\n'
  phase_start=$SECONDS
}

./scripts/install-deps.sh

# Both trees build with Ninja, which compiles a target's sources while the libraries it links are
# still being built (with make, each target waits for the ones before it). A tree configured
# earlier with another generator is configured afresh.
configure() {
  local dir="$1"
  shift
  if [ -f "$dir/CMakeCache.txt" ] && ! grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' "$dir/CMakeCache.txt"; then
    echo "test.sh: $dir was configured with another generator; configuring it again for Ninja"
    rm -rf "$dir"
  fi
  cmake -G Ninja -S . -B "$dir" "$@" >/dev/null
}

echo "== core tests under ASan + UBSan =="
configure build-asan -DCMAKE_BUILD_TYPE=Debug -DPATCHCULL_SANITIZE=ON \
  -DPATCHCULL_WITH_GL=OFF -DPATCHCULL_WITH_VULKAN=OFF -DPATCHCULL_BUILD_BENCHMARKS=OFF -DPATCHCULL_BUILD_EXAMPLES=OFF \
  -DPATCHCULL_BUILD_TOOLS=OFF -DPATCHCULL_WIDE_SIMD_TARGETS_ONLY=ON
cmake --build build-asan -j"$JOBS" --target patchcull_core_tests
ASAN_OPTIONS=detect_leaks=1 ctest --test-dir build-asan -j"$JOBS" -L core --output-on-failure
end_phase "sanitizer build and core suite"

echo "== fuzz campaign (libFuzzer, clang: OBJ reader and PNG loader, 20 s side by side) =="
./scripts/fuzz.sh 20
end_phase "fuzz campaign"

echo "== full suite (Release) =="
configure build -DCMAKE_BUILD_TYPE=Release -DPATCHCULL_WERROR=ON \
  -DPATCHCULL_PACKAGE_CPU_BUILD_DIR="$PWD/build-asan"
cmake --build build -j"$JOBS"
end_phase "Release build"
status=0
ctest --test-dir build -j"$JOBS" --output-on-failure || status=$?
end_phase "Release suite"
printf 'test.sh phases (wall clock, %s cores):\n%s' "$JOBS" "$phases"
exit "$status"
