#!/usr/bin/env python3
"""`--cull auto` against `none` and `all` on the default scene (gl/cull_auto_policy.h: the per-object
switch of Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation", §6.3),
for docs/PERFORMANCE.md.

Usage: python3 scripts/cull_auto_bench.py [BUILD_DIR] [ROUNDS] [FRAMES] [LEVELS]
       (defaults: build, 6, 24, 1,4,8,16)

Per round and level (--tess 1, 4, 8, 16), the three runs back to back (interleaved, their order
rotated from round to round so that none is always first):
  render default --cull none|all|auto --tess L --frames FRAMES --json
Each run's time is the mean of ms.total over frames 1..FRAMES-1 (frame 0 compiles the pass
programs and starts with half the patches tagged visible; auto's bootstrap frames 1-2, culled
while the costs are measured, are counted). On llvmpipe the pipeline times its passes with the
wall clock around glFinish (FrameStats::timing = wall-clock): other processes' load shows in the
times, hence the rounds. Prints per level the medians over rounds of auto/none, auto/all,
best/none (best = the faster of none and all in that round) and auto/best, with their min..max
over rounds, and each mode's run-to-run spread ((max - min) / median of its per-round times).
Also prints the fit of none's per-patch time against the level, p(L) = A + B L^2 (A / B: the
per-patch cost that does not grow with the factor, in units of t^2; cull_auto_policy.h's c0).
"""
import json
import os
import statistics
import subprocess
import sys

BUILD = sys.argv[1] if len(sys.argv) > 1 else "build"
ROUNDS = int(sys.argv[2]) if len(sys.argv) > 2 else 6
FRAMES = int(sys.argv[3]) if len(sys.argv) > 3 else 24
CLI = os.path.join(BUILD, "patchcull")
LEVELS = tuple(int(x) for x in sys.argv[4].split(",")) if len(sys.argv) > 4 else (1, 4, 8, 16)
MODES = ("none", "all", "auto")


def render(mode, level):
    cmd = [CLI, "render", "default", "--cull", mode, "--tess", str(level), "--frames", str(FRAMES), "--json"]
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)


def mean_total(result):
    frames = result["frames"][1:]
    return sum(f["ms"]["total"] for f in frames) / len(frames)


def culled_objects(result):
    frames = result["frames"][1:]
    return sum(sum(o["culling"] == "on" for o in f["auto_objects"]) for f in frames) / len(frames)


def load():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def spread(values):
    return (max(values) - min(values)) / statistics.median(values)


def main():
    times = {(L, m): [] for L in LEVELS for m in MODES}
    auto_on = {L: [] for L in LEVELS}
    none_per_patch = {L: [] for L in LEVELS}
    renderer = ""
    loads = [load()]
    for r in range(ROUNDS):
        for L in LEVELS:
            order = MODES[r % 3:] + MODES[:r % 3]
            for m in order:
                result = render(m, L)
                renderer = result["renderer"]
                times[(L, m)].append(mean_total(result))
                if m == "auto":
                    auto_on[L].append(culled_objects(result))
                if m == "none":
                    none_per_patch[L].append(mean_total(result) / result["patches"])
        loads.append(load())
        print(f"round {r + 1}/{ROUNDS} done, load {loads[-1]}", file=sys.stderr)

    print(f"renderer: {renderer}; {ROUNDS} rounds x {FRAMES} frames (frames 1..{FRAMES - 1} timed), 640x360")
    print(f"load average (1, 5, 15 min) before and after each round: {' | '.join(loads)}")
    print()
    print("| level | none ms | all ms | auto ms | auto/none | auto/all | best/none | auto/best | objects culled by auto"
          " | spread none / all / auto |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for L in LEVELS:
        n, a, u = (times[(L, m)] for m in MODES)
        ratio = {
            "auto/none": [u[i] / n[i] for i in range(ROUNDS)],
            "auto/all": [u[i] / a[i] for i in range(ROUNDS)],
            "best/none": [min(n[i], a[i]) / n[i] for i in range(ROUNDS)],
            "auto/best": [u[i] / min(n[i], a[i]) for i in range(ROUNDS)],
        }

        def cell(values):
            return f"{statistics.median(values):.2f} ({min(values):.2f}..{max(values):.2f})"

        print(f"| {L} | {statistics.median(n):.1f} | {statistics.median(a):.1f} | {statistics.median(u):.1f} | "
              + " | ".join(cell(ratio[k]) for k in ("auto/none", "auto/all", "best/none", "auto/best"))
              + f" | {statistics.mean(auto_on[L]):.1f} of 6 | "
              + f"{spread(n) * 100:.0f}% / {spread(a) * 100:.0f}% / {spread(u) * 100:.0f}% |")
        rows.append({"level": L, "none_ms": n, "all_ms": a, "auto_ms": u, "auto_objects_culled": auto_on[L],
                     **{k: v for k, v in ratio.items()}})
    # p(L) = A + B L^2 by least squares over the levels' median per-patch times of none.
    if len(LEVELS) < 2:
        print(json.dumps({"renderer": renderer, "rounds": ROUNDS, "frames": FRAMES, "loads": loads, "levels": rows}))
        return
    xs = [float(L * L) for L in LEVELS]
    ys = [statistics.median(none_per_patch[L]) for L in LEVELS]
    mx, my = statistics.mean(xs), statistics.mean(ys)
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    a = my - b * mx
    print()
    print(f"none per patch: p(L) = {a * 1000:.2f} us + {b * 1000:.3f} us * L^2 (A/B = {a / b:.1f}); "
          + ", ".join(f"L{L}: {y * 1000:.2f} us" for L, y in zip(LEVELS, ys)))
    print(json.dumps({"renderer": renderer, "rounds": ROUNDS, "frames": FRAMES, "loads": loads, "levels": rows}))


if __name__ == "__main__":
    main()
