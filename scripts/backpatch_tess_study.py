#!/usr/bin/env python3
"""Back-patch culling against the tessellation level (Loop, Niessner & Eisenacher, "Effective
Back-Patch Culling for Hardware Tessellation", Fig. 2 and Sec. 7): frame time of no culling,
TCONE, NCONE and PTP on one model, measured with `patchcull render --json`
(docs/PERFORMANCE.md, "Back-patch culling against the tessellation level").

Usage: python3 scripts/backpatch_tess_study.py [--cli PATH] [--levels 1,2,4,8,16] [--size WxH]
                                               [--frames N] [--rounds R] [--json FILE]

Scene: BigGuy alone (1450 ACC patches), a still camera with the whole object in view (the same
camera as scripts/sathe_study.py's "whole" setup), written to a temporary directory.
Per level and round, four runs back to back, so that each ratio compares runs seconds apart:
  render SCENE.json --cull none                                   (the reference)
  render SCENE.json --cull backpatch --backpatch tcone|ncone|ptp
each with --tess L --size WxH --frames N --json. A time is the median of ms.total (and of
ms.cull, the cull pass alone) over frames 1..N-1 (frame 0 compiles the shaders); the table prints
each culled time over the unculled one (< 1: culling pays), the cull-pass ms and the culled
fraction. With --rounds R > 1 a ratio is the median over rounds. "min" ratios divide the fastest
frame of all rounds by the fastest unculled one (other load only ever adds time).
Errors (a bad flag, a CLI that fails) are one line naming the flag or the command, exit status 2.
"""
import json
import os
import statistics
import sys
import tempfile

import render_study

PROG = "backpatch_tess_study.py"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODES = (("none", ["--cull", "none"]),
         ("tcone", ["--cull", "backpatch", "--backpatch", "tcone"]),
         ("ncone", ["--cull", "backpatch", "--backpatch", "ncone"]),
         ("ptp", ["--cull", "backpatch", "--backpatch", "ptp"]))
SCENE = {"name": "backpatch_tess_bigguy",
         "objects": [{"model": "bigguy", "transform": {"position": [0, 0, 0], "height": 1},
                      "animation": {"deform": False}}],
         "camera": {"orbit": {"target": [0, 0.5, 0], "distance": 2.6, "height": 0.3, "degrees_per_frame": 0}}}


def fail(message):
    render_study.fail(PROG, message)


def render(cli, path, level, size, frames, mode_args):
    out, timed = render_study.render_json(PROG, cli, path, level, size, frames, mode_args)
    return {"ms": statistics.median(f["ms"]["total"] for f in timed),
            "ms_min": min(f["ms"]["total"] for f in timed),
            "cull_ms": statistics.median(f["ms"]["cull"] for f in timed),
            "culled": out["frames"][-1]["backpatch_culled"], "patches": out["patches"]}


def parse_levels(value):
    try:
        levels = [int(t) for t in value.split(",")]
    except ValueError:
        fail(f"--levels: expected a comma-separated list of integers, got {value!r}")
    for v in levels:
        if not 1 <= v <= 64:
            fail(f"--levels: level {v} is outside 1..64")
    return "levels", levels


def parse_args(argv):
    defaults = {"cli": os.path.join(ROOT, "build", "patchcull"), "levels": [1, 2, 4, 8, 16], "size": "320x180",
                "frames": 3, "rounds": 1, "json": None}
    return render_study.parse_options(PROG, __doc__, argv, defaults, {"--levels": parse_levels})


def main(argv):
    opts = parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory(prefix="backpatch_tess_") as tmp:
        path = os.path.join(tmp, "bigguy.json")
        with open(path, "w") as f:
            json.dump(SCENE, f)
        for level in opts["levels"]:
            runs = {m: [] for m, _ in MODES}
            for _ in range(opts["rounds"]):
                for mode, args in MODES:
                    runs[mode].append(render(opts["cli"], path, level, opts["size"], opts["frames"], args))
            row = {"level": level, "patches": runs["none"][0]["patches"]}
            for mode, _ in MODES:
                row[f"{mode}_ms"] = statistics.median(r["ms"] for r in runs[mode])
                row[f"{mode}_ms_min"] = min(r["ms_min"] for r in runs[mode])
                row[f"{mode}_cull_ms"] = statistics.median(r["cull_ms"] for r in runs[mode])
                row[f"{mode}_culled"] = runs[mode][0]["culled"]
            line = f"L{level:<3} none {row['none_ms']:8.1f} ms"
            for mode in ("tcone", "ncone", "ptp"):
                row[f"{mode}_ratio"] = statistics.median(c["ms"] / n["ms"] for c, n in zip(runs[mode], runs["none"]))
                row[f"{mode}_ratio_min"] = row[f"{mode}_ms_min"] / row["none_ms_min"]
                line += (f" | {mode} {row[f'{mode}_ms']:8.1f} ms x{row[f'{mode}_ratio']:.3f}"
                         f" (min x{row[f'{mode}_ratio_min']:.3f}, cull {row[f'{mode}_cull_ms']:.2f} ms,"
                         f" {row[f'{mode}_culled'] / row['patches']:.0%} culled)")
            rows.append(row)
            print(line, flush=True)
    result = {"size": opts["size"], "frames": opts["frames"], "rounds": opts["rounds"],
              "load_after": os.getloadavg(), "rows": rows}
    if opts["json"]:
        try:
            with open(opts["json"], "w") as f:
                json.dump(result, f, indent=1)
        except OSError as e:
            fail(f"--json: {opts['json']}: {e.strerror}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
