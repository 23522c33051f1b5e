#!/usr/bin/env bash
# Fuzz campaign over the input loaders (README "Fuzzing"): builds the libFuzzer targets in fuzz/
# with clang (ASan + UBSan) in build-fuzz and runs them side by side for SECONDS (default 20) from the
# checked-in corpus fuzz/corpus/<target>. New inputs go to build-fuzz/corpus-<target> (kept
# between runs; the checked-in corpus is never written). Exits 1 on a crash, a sanitizer report,
# an input that runs over 5 s, one that needs over 2 GB, or a broken check of fuzz/input_checks.h;
# the input is saved under build-fuzz/artifacts/. scripts/test.sh runs it with the default.
#   scripts/fuzz.sh [SECONDS] [obj|png ...]
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_TARGET="${1:-20}"
if [ "$#" -gt 0 ]; then shift; fi
TARGETS=(obj png)
if [ "$#" -gt 0 ]; then TARGETS=("$@"); fi
CXX_FUZZ="${PATCHCULL_FUZZ_CXX:-clang++-14}"
if ! command -v "$CXX_FUZZ" >/dev/null; then
  echo "fuzz: $CXX_FUZZ not found (scripts/install-deps.sh installs clang-14 and libclang-rt-14-dev)" >&2
  exit 1
fi

cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$CXX_FUZZ" \
  -DPATCHCULL_BUILD_FUZZERS=ON -DPATCHCULL_BUILD_TESTS=OFF -DPATCHCULL_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target patchcull_obj_fuzz patchcull_png_fuzz
mkdir -p build-fuzz/artifacts
# The targets run at the same time (one process each, single-threaded), so the campaign takes
# SECONDS of wall clock on a machine with a core per target.
pids=()
for target in "${TARGETS[@]}"; do
  work="build-fuzz/corpus-$target"
  log="build-fuzz/fuzz-$target.log"
  mkdir -p "$work"
  echo "== fuzz $target: ${SECONDS_PER_TARGET} s (log: $log) =="
  "build-fuzz/fuzz/patchcull_${target}_fuzz" -max_total_time="$SECONDS_PER_TARGET" -timeout=5 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="build-fuzz/artifacts/$target-" \
    "$work" "fuzz/corpus/$target" >"$log" 2>&1 &
  pids+=("$!")
done
failed=0
for i in "${!TARGETS[@]}"; do
  target="${TARGETS[$i]}"
  log="build-fuzz/fuzz-$target.log"
  if ! wait "${pids[$i]}"; then
    tail -n 40 "$log"
    echo "fuzz: patchcull_${target}_fuzz failed; the input is under build-fuzz/artifacts/" >&2
    failed=1
    continue
  fi
  echo "fuzz $target: $(grep -E "^Done [0-9]+ runs" "$log" || echo "no summary line")"
done
exit "$failed"
