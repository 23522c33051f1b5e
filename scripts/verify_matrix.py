#!/usr/bin/env python3
"""`render --verify` over the verified matrix of inputs (docs/RESULTS.md, "Verified matrix").

Usage: python3 scripts/verify_matrix.py [BUILD_DIR] [--levels 1,4,16,64] [--size WxH] [--frames N]

Both shipped models x both schemes (acc, osd) x every cull mode (none, frustum, occlusion, and
backpatch / all with each back-patch method tcone, ncone, ptp) x the tessellation levels. Each
run renders an animated camera path with `--verify` (every frame against its unculled render,
false culls judged per patch, depth ties apart) and prints one row: model, scheme, mode, level,
patches culled per reason (summed over frames), depth-tie pixels, false culls. Exits 1 when any
run reports a false cull.
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("build", nargs="?", default="build")
    ap.add_argument("--levels", default="1,4,16,64")
    ap.add_argument("--size", default="512x512")
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--models", default="bigguy.obj,monsterfrog.obj")
    args = ap.parse_args()
    cli = os.path.join(args.build, "patchcull")
    modes = [("none", "tcone"), ("frustum", "tcone"), ("occlusion", "tcone")]
    modes += [(m, b) for m in ("backpatch", "all") for b in ("tcone", "ncone", "ptp")]
    total_false = 0
    start = time.time()
    print(f"render --verify, {args.size}, {args.frames} frames per run")
    print(f"{'model':<16} {'scheme':<6} {'mode':<16} {'level':>5} {'frustum':>8} {'back':>8} {'occl':>8} "
          f"{'ties':>6} {'false':>6}")
    for name in args.models.split(","):
        path = os.path.join(ROOT, "data", "models", name)
        for scheme in ("acc", "osd"):
            for mode, backpatch in modes:
                for level in args.levels.split(","):
                    cmd = [cli, "render", path, "--scheme", scheme, "--cull", mode, "--backpatch", backpatch,
                           "--tess", level, "--size", args.size, "--frames", str(args.frames), "--verify", "--json"]
                    run = subprocess.run(cmd, capture_output=True, text=True)
                    if run.returncode not in (0, 1):
                        print(" ".join(cmd), "->", run.returncode, run.stderr.strip(), file=sys.stderr)
                        return 2
                    j = json.loads(run.stdout)
                    sums = {k: sum(f[k] for f in j["frames"])
                            for k in ("frustum_culled", "backpatch_culled", "occlusion_culled", "depth_ties")}
                    total_false += j["false_culls"]
                    label = mode if mode in ("none", "frustum", "occlusion") else f"{mode} {backpatch}"
                    print(f"{name:<16} {scheme:<6} {label:<16} {level:>5} {sums['frustum_culled']:>8} "
                          f"{sums['backpatch_culled']:>8} {sums['occlusion_culled']:>8} {sums['depth_ties']:>6} "
                          f"{j['false_culls']:>6}", flush=True)
    print(f"false culls in total: {total_false} ({time.time() - start:.0f} s)")
    return 1 if total_false else 0


if __name__ == "__main__":
    sys.exit(main())
