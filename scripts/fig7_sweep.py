#!/usr/bin/env python3
"""Cull-pass time against patch count on the GPU pipeline for undisplaced and displaced patches:
Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation", Fig. 7 (left), whose
curves are NoDisp (frustum + Hi-Z occlusion of the control points), and the displaced kernels
with the camera-aligned frustum and no cone (Full), the approximate cone of normals (ACoN) and
the exact cone of normals (CoN).

Usage: python3 scripts/fig7_sweep.py [BUILD_DIR] [DATA_DIR]   (defaults: build, docs/figures/data)

Writes DATA_DIR/fig7/<curve>_split<S>.json, each the stdout of one command:
  NoDisp: patchcull render data/models/monsterfrog.obj --split S --frames 4 --tess 1
          --size 256x256 --cull occlusion --displace none --json
  Full, ACoN, CoN: the same with --displace procedural --bound caf --cone full|acon|con
          (every patch displaced by the procedural map, scale 0.02), and oobb_acon: --bound oobb
          --cone acon (the paper: the bounds of Munkberg et al. cost about the same, +-3%)
for S = 0, 1, 2, 3 (1292, 5168, 20672 and 82688 patches). scripts/plot_figures.py draws them as
fig7_cull_pass_displaced.png: "ms.cull" (the whole flag chain: status begin, frustum, occlusion or
the displaced pass, status end) averaged over frames 1..3 (frame 0 compiles the programs).
On Mesa llvmpipe the compute passes run on the CPU cores (wall clock around glFinish), so the
times are CPU times of the GLSL kernels, not a GPU's. About two minutes on 2 cores.
Bad arguments: one line naming BUILD_DIR or DATA_DIR, exit status 2.
"""
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROG = "fig7_sweep.py"
FROG = os.path.join(ROOT, "data", "models", "monsterfrog.obj")
CURVES = [("nodisp", ["--displace", "none"])] + [
    (cone, ["--displace", "procedural", "--bound", "caf", "--cone", cone]) for cone in ("full", "acon", "con")] + [
    ("oobb_acon", ["--displace", "procedural", "--bound", "oobb", "--cone", "acon"])]
SPLITS = (0, 1, 2, 3)


def fail(message):
    text = message.encode("ascii", "backslashreplace").decode("ascii").replace("\n", "\\n")
    print(f"{PROG}: error: {text[:500]}", file=sys.stderr)
    sys.exit(2)


def main(argv):
    if len(argv) > 2 or any(a.startswith("-") for a in argv):
        fail(f"usage: {PROG} [BUILD_DIR] [DATA_DIR]")
    build = argv[0] if argv else os.path.join(ROOT, "build")
    data = argv[1] if len(argv) > 1 else os.path.join(ROOT, "docs", "figures", "data")
    cli = os.path.join(build, "patchcull")
    if not (os.path.isfile(cli) and os.access(cli, os.X_OK)):
        fail(f"BUILD_DIR: {cli} is not an executable (build the patchcull_cli target first)")
    out_dir = os.path.join(data, "fig7")
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as e:
        fail(f"DATA_DIR: cannot create {out_dir} ({e.strerror})")
    for split in SPLITS:
        for name, args in CURVES:
            cmd = [cli, "render", FROG, "--split", str(split), "--frames", "4", "--tess", "1", "--size", "256x256",
                   "--cull", "occlusion", *args, "--json"]
            run = subprocess.run(cmd, capture_output=True, text=True)
            if run.returncode != 0:
                fail(f"{' '.join(cmd[1:])}: exit status {run.returncode}: {run.stderr.strip()[:300]}")
            result = json.loads(run.stdout)
            path = os.path.join(out_dir, f"{name}_split{split}.json")
            with open(path, "w", encoding="utf-8") as f:
                f.write(run.stdout)
            cull = [f["ms"]["cull"] for f in result["frames"][1:]]
            print(f"{name:>6} split {split}: {result['patches']:>6} patches, {result['displaced_patches']:>6} displaced, "
                  f"cull {sum(cull) / len(cull):8.2f} ms", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
