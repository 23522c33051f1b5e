#!/usr/bin/env bash
# 2-core scaling of every SIMD cull kernel: runs bench/memory_roof_bench.cpp's
# scaling/<kernel>/{1_thread,all_threads}/N rows (plain layout, N = 256 .. 65536 patches; all
# threads = the batch split into one range per thread, a multiple of 16 patches each, over
# parallel_for_ranges) and prints, per kernel and size, M patches/s on one thread and on all
# threads and the speedup, then the smallest size from which threading pays (speedup >= 1.1 at it
# and at every larger size). Best of the repetitions (the fastest run is the least disturbed one
# on a shared machine); `uptime` is printed before and after.
#
# Usage: scripts/kernel_scaling.sh [build-dir] [repetitions] [min-time-seconds]
#   defaults: build 5 0.1.  Extra kernels' rows are picked up by name (scaling/<kernel>/...).
set -euo pipefail
build=${1:-build}
reps=${2:-5}
min_time=${3:-0.1}
bench="$build/bench/patchcull_bench"
[ -x "$bench" ] || { echo "kernel_scaling.sh: $bench not found (build the patchcull_bench target)" >&2; exit 2; }
json=$(mktemp)
trap 'rm -f "$json"' EXIT
echo "before: $(uptime)"
"$bench" --benchmark_filter='^scaling/' --benchmark_repetitions="$reps" --benchmark_min_time="$min_time" \
    --benchmark_format=json >"$json" 2>/dev/null
echo "after:  $(uptime)"
python3 - "$json" <<'EOF'
import json, sys
from collections import defaultdict
runs = json.load(open(sys.argv[1]))
best = defaultdict(float)   # (kernel, threads, n) -> max items/s
for b in runs["benchmarks"]:
    if b.get("run_type") != "iteration":
        continue
    parts = b["run_name"].split("/")  # scaling/<kernel>/<threads>/<n>/real_time
    kernel, threads, n = parts[1], parts[2], int(parts[3])
    best[(kernel, threads, n)] = max(best[(kernel, threads, n)], b["items_per_second"])
threads_n = int(next(b for b in runs["benchmarks"] if "/all_threads/" in b["run_name"])["threads"])
kernels = sorted({k for k, _, _ in best}, key=lambda k: ["frustum", "frustum_disp", "tcone", "ncone", "ptp",
                                                         "occlusion", "fused"].index(k) if k in
                 ["frustum", "frustum_disp", "tcone", "ncone", "ptp", "occlusion", "fused"] else 99)
sizes = sorted({n for _, _, n in best})
print(f"\nM patches/s, 1 thread / {threads_n} threads (speedup); best of the repetitions")
print(f"{'kernel':<13}" + "".join(f"{n:>20}" for n in sizes))
pays = {}
for k in kernels:
    row, speed = [], {}
    for n in sizes:
        one, all_ = best.get((k, "1_thread", n), 0), best.get((k, "all_threads", n), 0)
        s = all_ / one if one else 0
        speed[n] = s
        row.append(f"{one / 1e6:6.1f}/{all_ / 1e6:6.1f} ({s:4.2f})")
    print(f"{k:<13}" + "".join(f"{c:>20}" for c in row))
    from_n = None
    for n in sizes:
        if all(speed[m] >= 1.1 for m in sizes if m >= n):
            from_n = n
            break
    pays[k] = from_n
print("\nthreading pays (speedup >= 1.1 from this size on):")
for k in kernels:
    print(f"  {k:<13} {pays[k] if pays[k] else 'never in 256..65536'}")
EOF
