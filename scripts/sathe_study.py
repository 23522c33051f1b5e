#!/usr/bin/env python3
"""Sathe's study ("View Frustum Culling of Catmull-Clark Patches in DirectX 11", Game Programming
Gems 8, Figs. 1.4.6-1.4.8): frame time against the tessellation level (edge LOD) with and without
frustum culling, in two camera setups, measured with `patchcull render --json`
(docs/PERFORMANCE.md, "Sathe's study").

Usage: python3 scripts/sathe_study.py [--cli PATH] [--scenes bigguy,default] [--levels 2,4,8,16]
                                      [--size WxH] [--frames N] [--rounds R] [--json FILE]

Setups (scene files written to a temporary directory, still cameras, no animation):
  whole  the whole object in view: nothing can be culled, so culling is pure overhead (Fig. 1.4.6);
  half   the camera turned aside: about half of the patches outside the view (Figs. 1.4.7, 1.4.8).
Scenes: `bigguy` (BigGuy alone, 1450 ACC patches) and `default` (the default scene: three BigGuys
and three displaced MonsterFrogs, 8226 patches, with its occluders).
Per scene, setup, level and round, three runs back to back, so that each ratio compares runs
taken seconds apart on the same machine state:
  render SCENE.json --cull none                     (no cull test: the reference)
  render SCENE.json --cull frustum --frustum hull   (Niessner & Loop's control-point test)
  render SCENE.json --cull frustum --frustum aabb   (Sathe's box grown by max |D|)
each with --tess L --size WxH --frames N --json. A time is the median of ms.total over frames
1..N-1 (frame 0 compiles the shaders); the table prints each culled time over the unculled one
(< 1: culling pays) and the culled fraction. With --rounds R > 1 a ratio is the median over rounds.
The "min" ratios divide the fastest frame of all rounds by the fastest unculled one: on a shared
machine the other load only ever adds time, so the minimum is the steadier estimate.
Errors (a bad flag, a CLI that fails) are one line naming the flag or the command, exit status 2.
"""
import json
import os
import statistics
import sys
import tempfile

import render_study

PROG = "sathe_study.py"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODES = (("none", ["--cull", "none"]), ("hull", ["--cull", "frustum", "--frustum", "hull"]),
         ("aabb", ["--cull", "frustum", "--frustum", "aabb"]))
# Still cameras (orbit with 0 degrees per frame). half: the view centre moved aside so that the
# left edge of the view crosses the object's middle (calibrated with these commands: about 45-50%
# of the patches outside the frustum).
CAMERAS = {
    "bigguy": {
        "whole": {"orbit": {"target": [0, 0.5, 0], "distance": 2.6, "height": 0.3, "degrees_per_frame": 0}},
        "half": {"orbit": {"target": [1.75, 0.5, 0], "distance": 1.8, "height": 0, "degrees_per_frame": 0}},
    },
    "default": {
        "whole": {"orbit": {"target": [0.1, 0.4, -0.7], "distance": 5.5, "height": 1.2, "degrees_per_frame": 0},
                  "fovy_degrees": 45, "z_near": 0.05, "z_far": 30},
        "half": {"orbit": {"target": [2.5, 0.4, -0.7], "distance": 3.2, "height": 0.6, "degrees_per_frame": 0},
                 "fovy_degrees": 45, "z_near": 0.05, "z_far": 30},
    },
}


def fail(message):
    render_study.fail(PROG, message)


def scene_json(scene, setup):
    if scene == "bigguy":
        data = {"name": "sathe_bigguy",
                "objects": [{"model": "bigguy", "transform": {"position": [0, 0, 0], "height": 1},
                             "animation": {"deform": False}}]}
    else:
        with open(os.path.join(ROOT, "data", "scenes", "default.json")) as f:
            data = json.load(f)
        for o in data["objects"]:
            o.setdefault("animation", {})["deform"] = False
    data["camera"] = CAMERAS[scene][setup]
    return data


def render(cli, path, level, size, frames, mode_args):
    out, timed = render_study.render_json(PROG, cli, path, level, size, frames, mode_args)
    times = [f["ms"]["total"] for f in timed]
    return {"ms": statistics.median(times), "ms_min": min(times),
            "frustum_culled": out["frames"][-1]["frustum_culled"], "patches": out["patches"]}


def parse_list(flag, text, convert, allowed=None):
    items = [t for t in text.split(",")]
    try:
        values = [convert(t) for t in items]
    except ValueError:
        fail(f"{flag}: expected a comma-separated list, got {text!r}")
    for v in values:
        if allowed is not None and v not in allowed:
            fail(f"{flag}: {v!r} is not one of {','.join(allowed)}")
        if allowed is None and not 1 <= v <= 64:
            fail(f"{flag}: level {v} is outside 1..64")
    return values


def parse_args(argv):
    defaults = {"cli": os.path.join(ROOT, "build", "patchcull"), "scenes": ["bigguy", "default"],
                "levels": [2, 4, 8, 16], "size": "480x270", "frames": 4, "rounds": 1, "json": None}
    extra = {"--scenes": lambda v: ("scenes", parse_list("--scenes", v, str, tuple(CAMERAS))),
             "--levels": lambda v: ("levels", parse_list("--levels", v, int))}
    return render_study.parse_options(PROG, __doc__, argv, defaults, extra)


def main(argv):
    opts = parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory(prefix="sathe_study_") as tmp:
        for scene in opts["scenes"]:
            for setup in ("whole", "half"):
                path = os.path.join(tmp, f"{scene}_{setup}.json")
                with open(path, "w") as f:
                    json.dump(scene_json(scene, setup), f)
                for level in opts["levels"]:
                    runs = {m: [] for m, _ in MODES}
                    for _ in range(opts["rounds"]):
                        for mode, args in MODES:
                            runs[mode].append(render(opts["cli"], path, level, opts["size"], opts["frames"], args))
                    row = {"scene": scene, "setup": setup, "level": level, "patches": runs["none"][0]["patches"]}
                    for mode, _ in MODES:
                        row[f"{mode}_ms"] = statistics.median(r["ms"] for r in runs[mode])
                        row[f"{mode}_culled"] = runs[mode][0]["frustum_culled"]
                        row[f"{mode}_ms_min"] = min(r["ms_min"] for r in runs[mode])
                    for mode in ("hull", "aabb"):
                        row[f"{mode}_ratio"] = statistics.median(
                            c["ms"] / n["ms"] for c, n in zip(runs[mode], runs["none"]))
                        row[f"{mode}_ratio_min"] = row[f"{mode}_ms_min"] / row["none_ms_min"]
                    rows.append(row)
                    print(f"{scene:8} {setup:5} L{level:<3} none {row['none_ms']:8.1f} ms | "
                          f"hull {row['hull_ms']:8.1f} ms x{row['hull_ratio']:.3f} "
                          f"({row['hull_culled'] / row['patches']:.0%} culled) | "
                          f"aabb {row['aabb_ms']:8.1f} ms x{row['aabb_ratio']:.3f} "
                          f"({row['aabb_culled'] / row['patches']:.0%} culled) | "
                          f"min: x{row['hull_ratio_min']:.3f} x{row['aabb_ratio_min']:.3f}", flush=True)
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
