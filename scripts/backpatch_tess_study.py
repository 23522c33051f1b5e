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
import subprocess
import sys
import tempfile

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
    # Printable and bounded, whatever an argument holds.
    text = message.encode("ascii", "backslashreplace").decode("ascii").replace("\n", "\\n")
    print(f"{PROG}: error: {text[:500]}", file=sys.stderr)
    sys.exit(2)


def render(cli, path, level, size, frames, mode_args):
    cmd = [cli, "render", path, "--tess", str(level), "--size", size, "--frames", str(frames), "--json", *mode_args]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as e:  # e.g. the binary being relinked by a build
        fail(f"--cli: {cli}: {e.strerror}")
    if r.returncode != 0:
        last = (r.stderr.strip().splitlines() or ["(no output)"])[-1]
        fail(f"{' '.join(cmd[1:])}: exit status {r.returncode}: {last}")
    out = json.loads(r.stdout)
    timed = out["frames"][1:]
    return {"ms": statistics.median(f["ms"]["total"] for f in timed),
            "ms_min": min(f["ms"]["total"] for f in timed),
            "cull_ms": statistics.median(f["ms"]["cull"] for f in timed),
            "culled": out["frames"][-1]["backpatch_culled"], "patches": out["patches"]}


def parse_args(argv):
    opts = {"cli": os.path.join(ROOT, "build", "patchcull"), "levels": [1, 2, 4, 8, 16], "size": "320x180",
            "frames": 3, "rounds": 1, "json": None}
    i = 0
    while i < len(argv):
        flag = argv[i]
        if flag in ("-h", "--help"):
            print(__doc__)
            sys.exit(0)
        if flag not in ("--cli", "--levels", "--size", "--frames", "--rounds", "--json"):
            fail(f"unknown option {flag!r} (see --help)")
        if i + 1 >= len(argv) or not argv[i + 1]:
            fail(f"{flag}: expected a value")
        value = argv[i + 1]
        i += 2
        if flag == "--cli":
            if not os.access(value, os.X_OK):
                fail(f"--cli: {value}: not an executable file")
            opts["cli"] = value
        elif flag == "--levels":
            try:
                levels = [int(t) for t in value.split(",")]
            except ValueError:
                fail(f"--levels: expected a comma-separated list of integers, got {value!r}")
            for v in levels:
                if not 1 <= v <= 64:
                    fail(f"--levels: level {v} is outside 1..64")
            opts["levels"] = levels
        elif flag == "--size":
            w, _, h = value.partition("x")
            if not (w.isdigit() and h.isdigit() and 16 <= int(w) <= 4096 and 16 <= int(h) <= 4096):
                fail(f"--size: expected WxH with 16..4096 each, got {value!r}")
            opts["size"] = value
        elif flag in ("--frames", "--rounds"):
            lo, hi = (2, 100) if flag == "--frames" else (1, 20)
            if not (value.isdigit() and lo <= int(value) <= hi):
                fail(f"{flag}: expected an integer in {lo}..{hi}, got {value!r}")
            opts[flag[2:]] = int(value)
        else:
            opts["json"] = value
    if not os.access(opts["cli"], os.X_OK):
        fail(f"--cli: {opts['cli']}: not an executable file (build patchcull_cli first)")
    return opts


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
