#!/usr/bin/env python3
"""CHC++'s two constants measured on this pipeline (docs/PERFORMANCE.md, "CHC++'s
constants"): the multiquery cost per object c1 (C(M) = 1 + c1 |M|, Mattausch, Bittner & Wimmer,
"CHC++: Coherent Hierarchical Culling Revisited") and the tight-bounding-volume factor sigma (boxes
refined while their area stays below sigma times the parent's). For each value it runs
`patchcull eval scene SCENE --methods chc++` (every frame verified) and prints queries,
multiqueries, proxy boxes, objects culled and frame time per frame, and the frame time's ratio to
the unculled frame of the same run (the comparable figure on a loaded machine); the value with the
lowest ratio is this pipeline's, where the differences stand out of the noise.

Usage: chcpp_constants.py [--cli PATH] [--scene SCENE] [--frames N] [--size WxH] [--tess L]
                          [--c1 LIST] [--sigma LIST] [--json OUT]
Defaults: build/patchcull, data/scenes/city_small.json, 8 frames, 320x180, level 4,
c1 0,0.05,0.1,0.25,0.5,1 (sigma 1.4), sigma 1,1.2,1.4,2,4 (c1 0.1).
Bad arguments: one line on stderr, exit status 2.
"""
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROG = "chcpp_constants.py"


def fail(message):
    text = message.encode("ascii", "backslashreplace").decode("ascii").replace("\n", "\\n")
    print(f"{PROG}: error: {text[:500]}", file=sys.stderr)
    sys.exit(2)


def number_list(flag, text, lo, hi):
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        fail(f"{flag}: expected comma-separated numbers, got {text!r}")
    if not values or len(values) > 16 or any(not (lo <= v <= hi) for v in values):
        fail(f"{flag}: expected 1..16 numbers in [{lo}, {hi}], got {text!r}")
    return values


def parse(argv):
    o = {"cli": os.path.join(ROOT, "build", "patchcull"), "scene": os.path.join(ROOT, "data", "scenes", "city_small.json"),
         "frames": 8, "size": "320x180", "tess": 4, "c1": [0, 0.05, 0.1, 0.25, 0.5, 1], "sigma": [1, 1.2, 1.4, 2, 4],
         "json": None}
    i = 0
    while i < len(argv):
        flag = argv[i]
        if flag in ("-h", "--help"):
            print(__doc__)
            sys.exit(0)
        if flag not in ("--cli", "--scene", "--frames", "--size", "--tess", "--c1", "--sigma", "--json"):
            fail(f"unknown option {flag!r} (see --help)")
        if i + 1 >= len(argv) or not argv[i + 1]:
            fail(f"{flag}: expected a value")
        value = argv[i + 1]
        i += 2
        if flag in ("--frames", "--tess"):
            lo, hi = (1, 1000) if flag == "--frames" else (1, 64)
            if not (value.isdigit() and lo <= int(value) <= hi):
                fail(f"{flag}: expected an integer in {lo}..{hi}, got {value!r}")
            o[flag[2:]] = int(value)
        elif flag == "--size":
            w, _, h = value.partition("x")
            if not (w.isdigit() and h.isdigit() and 1 <= int(w) <= 8192 and 1 <= int(h) <= 8192):
                fail(f"--size: expected WxH with 1..8192 each, got {value!r}")
            o["size"] = value
        elif flag == "--c1":
            o["c1"] = number_list(flag, value, 0, 100)
        elif flag == "--sigma":
            o["sigma"] = number_list(flag, value, 1, 16)
        else:
            o[flag[2:]] = value
    if not os.access(o["cli"], os.X_OK):
        fail(f"--cli: {o['cli']}: not an executable file (build patchcull_cli first)")
    return o


def run(o, c1, sigma):
    cmd = [o["cli"], "eval", "scene", o["scene"], "--methods", "chc++", "--frames", str(o["frames"]), "--size", o["size"],
           "--tess", str(o["tess"]), "--c1", str(c1), "--sigma", str(sigma), "--json"]
    r = subprocess.run(cmd, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    if r.returncode != 0:
        last = (r.stderr.strip().splitlines() or ["(no output)"])[-1]
        fail(f"{' '.join(cmd[1:])}: exit status {r.returncode}: {last}")
    out = json.loads(r.stdout)
    row = next(m for m in out["methods"] if m["name"] == "chc++")
    none = next(m for m in out["methods"] if m["name"] == "none")
    return {"c1": c1, "sigma": sigma, "queries": row["queries"], "multiqueries": row["multiqueries"],
            "multiqueries_passed": row["multiqueries_passed"], "proxy_boxes": row["proxy_boxes"],
            "objects_culled": row["objects_culled"], "pass1_ms": row["ms"]["pass1"], "frame_ms": row["ms"]["frame"],
            "none_frame_ms": none["ms"]["frame"], "frame_ratio": row["frame_ratio"], "false_culls": row["false_culls"]}


def main():
    o = parse(sys.argv[1:])
    rows = [run(o, c1, 1.4) for c1 in o["c1"]] + [run(o, 0.1, s) for s in o["sigma"]]
    print(f"{'c1':>6} {'sigma':>6} {'queries':>8} {'multi':>6} {'passed':>6} {'boxes':>7} {'culled':>7} "
          f"{'pass1 ms':>9} {'frame ms':>9} {'none ms':>8} {'ratio':>6} {'false':>5}")
    for r in rows:
        print(f"{r['c1']:6.2f} {r['sigma']:6.2f} {r['queries']:8.1f} {r['multiqueries']:6.1f} {r['multiqueries_passed']:6.1f} "
              f"{r['proxy_boxes']:7.1f} {r['objects_culled']:7.1f} {r['pass1_ms']:9.2f} {r['frame_ms']:9.2f} "
              f"{r['none_frame_ms']:8.2f} {r['frame_ratio']:6.2f} {r['false_culls']:5d}")
    if o["json"]:
        with open(o["json"], "w") as f:
            json.dump({"scene": o["scene"], "frames": o["frames"], "size": o["size"], "tess": o["tess"], "rows": rows}, f,
                      indent=1)
    return 1 if any(r["false_culls"] for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
