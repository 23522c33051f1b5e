#!/usr/bin/env bash
# GPU figures for the fused cull pass, ready for the day a GPU is lent (the `device`
# tool runs it in the repository root; on llvmpipe it runs too, slowly: SIDE=41 for a try).
#
# usage: OUT=DIR scripts/gpu_fused_figures.sh [BUILD_DIR]
#   BUILD_DIR (default: build-gpu) is configured (Release) and `patchcull` built there when it has
#   no binary yet. Writes under $OUT (default: ./gpu_fused_out):
#   (in ${TMPDIR:-/tmp}, not $OUT: ~40 MB) cube_SIDE.obj, a closed cube of SIDE x SIDE quads a side
#                             (SIDE=408: 998,784 quads, one acc patch each: the "1M patches" of
#                             the goal below), faces outward
#   render_*.json             every `patchcull render --json` run, as printed
#   gpu_fused_figures.json    the summary: per model and back-patch cone, the cull-pass time per
#                             frame (FrameStats::cull_ms: the whole flag chain, status passes
#                             included) of the separate passes and of the fused pass (--fused-pass),
#                             their ratio, the patches culled; the Hi-Z build (ms.hiz) at 1920x1080
#                             and 3840x2160 on the default scene; the renderer string.
# Every figure is the mean over frames 1..N-1 (frame 0 compiles the programs and primes the
# statuses). On a GPU the pipeline times its passes with GL_TIMESTAMP queries (gl_pipeline.h's
# TimingMethod::automatic), on llvmpipe with a wall clock around glFinish.
# Goal: the cull passes for 1M patches under 0.1 ms on an H100/H200-class GPU.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${1:-build-gpu}"
OUT="${OUT:-./gpu_fused_out}"
SIDE="${SIDE:-408}"
FRAMES="${FRAMES:-8}"
mkdir -p "$OUT"

if [ ! -x "$BUILD/patchcull" ]; then
    cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >"$OUT/cmake.log" 2>&1
    cmake --build "$BUILD" -j"$(nproc)" --target patchcull_cli >"$OUT/build.log" 2>&1
fi
CLI="$BUILD/patchcull"

CUBE="${TMPDIR:-/tmp}/patchcull_cube_$SIDE.obj"
if [ ! -s "$CUBE" ]; then
    python3 - "$SIDE" >"$CUBE" <<'PY'
# A closed cube of n x n quads per side on [0, 1]^3, vertices shared along edges and corners,
# every face counter-clockwise seen from outside (u x v points out).
import sys
n = int(sys.argv[1])
index = {}
lines = []
def vertex(p):
    if p not in index:
        index[p] = len(index) + 1
        lines.append(f"v {p[0] / n} {p[1] / n} {p[2] / n}")
    return index[p]
faces = []
for axis in range(3):
    for side in (0, n):
        a, b = (axis + 1) % 3, (axis + 2) % 3  # e_a x e_b = e_axis
        if side == 0:
            a, b = b, a  # outward is -e_axis
        for j in range(n):
            for i in range(n):
                corners = []
                for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = [0, 0, 0]
                    p[axis] = side
                    p[a] = i + di
                    p[b] = j + dj
                    corners.append(vertex(tuple(p)))
                faces.append("f " + " ".join(map(str, corners)))
sys.stdout.write("\n".join(lines + faces) + "\n")
PY
fi

run() {  # run NAME ARGS...: patchcull render ARGS --json > $OUT/render_NAME.json
    local name="$1"
    shift
    "$CLI" render "$@" --json >"$OUT/render_$name.json"
}

for model in cube default; do
    input="$CUBE"
    [ "$model" = default ] && input=default
    for cone in tcone ncone; do
        for pass in separate fused; do
            flag=()
            [ "$pass" = fused ] && flag=(--fused-pass)
            run "${model}_${cone}_${pass}" "$input" --frames "$FRAMES" --size 1920x1080 --tess 1 --cull all \
                --backpatch "$cone" "${flag[@]}"
        done
    done
done
for size in 1920x1080 3840x2160; do
    run "hiz_$size" default --frames "$FRAMES" --size "$size" --tess 1 --cull occlusion
done

python3 - "$OUT" "$SIDE" <<'PY'
import json, os, sys
out, side = sys.argv[1], int(sys.argv[2])
def load(name):
    with open(os.path.join(out, f"render_{name}.json")) as f:
        return json.load(f)
def mean(r, get):
    frames = r["frames"][1:] or r["frames"]
    return sum(get(f) for f in frames) / len(frames)
summary = {"cube_side": side, "cull": [], "hiz": []}
for model in ("cube", "default"):
    for cone in ("tcone", "ncone"):
        row = {"model": model, "cone": cone}
        for p in ("separate", "fused"):
            r = load(f"{model}_{cone}_{p}")
            row["patches"] = r["patches"]
            row["renderer"] = r["renderer"]
            row[f"{p}_cull_ms"] = mean(r, lambda f: f["ms"]["cull"])
            row[f"{p}_culled"] = mean(r, lambda f: f["frustum_culled"] + f["backpatch_culled"] + f["occlusion_culled"])
            row[f"{p}_ran_fused"] = all(f.get("fused_pass", False) for f in r["frames"])
        row["fused_over_separate"] = row["fused_cull_ms"] / row["separate_cull_ms"] if row["separate_cull_ms"] else None
        summary["cull"].append(row)
for size in ("1920x1080", "3840x2160"):
    r = load(f"hiz_{size}")
    summary["hiz"].append({"size": size, "hiz_ms": mean(r, lambda f: f["ms"]["hiz"]), "renderer": r["renderer"]})
with open(os.path.join(out, "gpu_fused_figures.json"), "w") as f:
    json.dump(summary, f, indent=1)
print(json.dumps(summary, indent=1))
PY
