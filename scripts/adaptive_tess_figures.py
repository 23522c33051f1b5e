#!/usr/bin/env python3
"""The adaptive-tessellation experiment of Niessner & Loop, "Patch-Based Occlusion Culling for
Hardware Tessellation" §6.3: frame time with and without culling under tessellation by
distance, on the default scene, measured with `patchcull render --json` (docs/PERFORMANCE.md).

Usage: python3 scripts/adaptive_tess_figures.py [BUILD_DIR] [ROUNDS]   (defaults: build, 2)

Per maximum level (--tess 2, 4, 8, 16, 32) and round, four runs back to back, so that each ratio
compares runs taken seconds apart on the same machine state:
  render default --tess-mode adaptive --tess L --cull none --frames 5 --json
  render default --tess-mode adaptive --tess L --cull all  --frames 5 --json
  render default --tess-mode uniform  --tess L --cull none --frames 5 --json   (for reference)
  render default --tess-mode uniform  --tess L --cull all  --frames 5 --json
Each time is the mean of ms.total over frames 1..4 (frame 0 compiles the shaders and starts with
half the patches tagged visible). On llvmpipe the renderer times every pass with the wall clock
around glFinish (FrameStats::timing = wall-clock, gl_renderer.h); on a GPU, with timer queries.
"""
import json
import os
import subprocess
import sys

BUILD = sys.argv[1] if len(sys.argv) > 1 else "build"
ROUNDS = int(sys.argv[2]) if len(sys.argv) > 2 else 2
CLI = os.path.join(BUILD, "patchcull")
LEVELS = (2, 4, 8, 16, 32)
FRAMES = 5


def render(*args):
    cmd = [CLI, "render", "default", *map(str, args), "--frames", str(FRAMES), "--json"]
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)


def mean(result, get):
    frames = result["frames"][1:]
    return sum(get(f) for f in frames) / len(frames)


def frame_ms(result):
    return mean(result, lambda f: f["ms"]["total"])


def culled_fraction(result):
    return mean(result, lambda f: f["frustum_culled"] + f["backpatch_culled"] + f["occlusion_culled"]) / result["patches"]


def main():
    print("uptime:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())
    print(f"renderer: {render('--size', '8x8')['renderer']}")
    print(f"default scene, 640x360, {FRAMES} frames, mean ms.total over frames 1..{FRAMES - 1}, {ROUNDS} rounds\n")
    header = (f"{'round':>5} {'tess':>4} | {'adapt none':>10} {'adapt all':>10} {'ratio':>6} {'culled':>7} | "
              f"{'unif none':>10} {'unif all':>10} {'ratio':>6} | {'adapt/unif none':>15}")
    print(header)
    totals = {}
    for r in range(ROUNDS):
        print("uptime:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip(), flush=True)
        for tess in LEVELS:
            runs = {}
            for mode in ("adaptive", "uniform"):
                for cull in ("none", "all"):
                    runs[mode, cull] = render("--tess-mode", mode, "--tess", tess, "--cull", cull)
                    assert runs[mode, cull]["tess_mode"] == mode
            t = {k: frame_ms(v) for k, v in runs.items()}
            for k, v in t.items():
                totals.setdefault((tess, *k), []).append(v)
            print(f"{r + 1:>5} {tess:>4} | {t['adaptive', 'none']:>10.1f} {t['adaptive', 'all']:>10.1f} "
                  f"{t['adaptive', 'all'] / t['adaptive', 'none']:>6.2f} "
                  f"{100 * culled_fraction(runs['adaptive', 'all']):>6.1f}% | "
                  f"{t['uniform', 'none']:>10.1f} {t['uniform', 'all']:>10.1f} "
                  f"{t['uniform', 'all'] / t['uniform', 'none']:>6.2f} | "
                  f"{t['adaptive', 'none'] / t['uniform', 'none']:>15.2f}", flush=True)
    print("\nmeans over rounds (ms): tess, adaptive none, adaptive all, ratio, uniform none, uniform all, ratio")
    for tess in LEVELS:
        m = {k: sum(totals[(tess, *k)]) / ROUNDS for k in (("adaptive", "none"), ("adaptive", "all"),
                                                             ("uniform", "none"), ("uniform", "all"))}
        print(f"{tess:>4} {m['adaptive', 'none']:>9.1f} {m['adaptive', 'all']:>9.1f} "
              f"{m['adaptive', 'all'] / m['adaptive', 'none']:>6.2f} {m['uniform', 'none']:>9.1f} "
              f"{m['uniform', 'all']:>9.1f} {m['uniform', 'all'] / m['uniform', 'none']:>6.2f}")
    print("uptime:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())


if __name__ == "__main__":
    main()
