#!/usr/bin/env python3
"""The object level's effect on `city` frames (G. Zachmann's lecture "Advanced
Visibility Computations"), from `patchcull render --json`, for docs/PERFORMANCE.md.

Usage: python3 scripts/object_level_bench.py [BUILD_DIR] [ROUNDS] [FRAMES] [TESS] [SCENE]
       (defaults: build, 4, 6, 8, city)

1. Frame time with and without the object level. Per round, the runs back to back (interleaved,
   their order rotated from round to round so that none is always first):
     render SCENE --objects none|frustum|bvh|bvh+backface --cull all --tess TESS --frames FRAMES --json
   A run's numbers are means over frames 1..FRAMES-1 (frame 0 compiles the pass programs and
   starts with half the patches tagged visible). Per mode: ms.total and the pass times (pass1,
   hiz, cull, pass2), patches skipped by the object level (objects.patches_culled: no pass
   touches them), patches culled by the patch passes (frustum + back-patch + occlusion), patches
   drawn (pass 1 + pass 2), occluder triangles culled, objects culled whole. Ratios to `none`
   are taken within a round (runs seconds apart), then their median (min..max over rounds);
   "spread" is (max - min) / median of a mode's per-round times. ms.total is the pipeline's frame
   (render_frame): the object level's own CPU time (SceneObjectLevel::cull, before render_frame)
   is not in it; bench/object_level_bench.cpp measures it.
2. Counts of the frustum-test variants (deterministic, so one run each, --cull none --tess 1 to
   keep the runs short; the object level does not depend on either):
     render SCENE --objects frustum|bvh [--plane-masking on|off] [--plane-coherence on|off]
            [--meta-bv on] --cull none --tess 1 --frames FRAMES --json
   per frame (1..FRAMES-1): plane_tests, plane tests per object, bvh_nodes_visited, objects
   culled, meta_rejected. Their times are bench/object_level_bench.cpp's.

The load average (/proc/loadavg) is printed before every round and at the end. Bad arguments
(ROUNDS 1..100, FRAMES 2..1000, TESS 1..64, a BUILD_DIR without patchcull) give one line on stderr
and exit status 2; a failing render gives its command and last error line, and its status.
"""
import json
import os
import statistics
import subprocess
import sys



def fail(message):
    """Bad input: one line naming what is wrong, exit status 2."""
    print(f"object_level_bench: {message}", file=sys.stderr)
    sys.exit(2)


def int_arg(index, name, default, low, high):
    if len(sys.argv) <= index:
        return default
    text = sys.argv[index]
    try:
        value = int(text)
    except ValueError:
        fail(f"{name}: '{text}' is not an integer")
    if not low <= value <= high:
        fail(f"{name}: {value} is outside {low}..{high}")
    return value


if len(sys.argv) > 6:
    fail(f"too many arguments ({len(sys.argv) - 1}; at most BUILD_DIR ROUNDS FRAMES TESS SCENE)")
BUILD = sys.argv[1] if len(sys.argv) > 1 else "build"
ROUNDS = int_arg(2, "ROUNDS", 4, 1, 100)
FRAMES = int_arg(3, "FRAMES", 6, 2, 1000)
TESS = int_arg(4, "TESS", 8, 1, 64)
SCENE = sys.argv[5] if len(sys.argv) > 5 else "city"
CLI = os.path.join(BUILD, "patchcull")
MODES = ("none", "frustum", "bvh", "bvh+backface")
VARIANTS = (
    ("frustum (flat), coherence on", ["--objects", "frustum", "--plane-coherence", "on"]),
    ("frustum (flat), coherence off", ["--objects", "frustum", "--plane-coherence", "off"]),
    ("bvh, masking off, coherence off", ["--objects", "bvh", "--plane-masking", "off", "--plane-coherence", "off"]),
    ("bvh, masking on, coherence off", ["--objects", "bvh", "--plane-masking", "on", "--plane-coherence", "off"]),
    ("bvh, masking off, coherence on", ["--objects", "bvh", "--plane-masking", "off", "--plane-coherence", "on"]),
    ("bvh, masking on, coherence on (default)", ["--objects", "bvh"]),
    ("bvh, masking + coherence + meta-BVs", ["--objects", "bvh", "--meta-bv", "on"]),
)


def load():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def render(args):
    cmd = [CLI, "render", SCENE, "--frames", str(FRAMES), "--json"] + args
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        last = run.stderr.strip().splitlines()[-1] if run.stderr.strip() else "no message"
        print(f"object_level_bench: `{' '.join(cmd)}` failed ({run.returncode}): {last}", file=sys.stderr)
        sys.exit(run.returncode if run.returncode == 2 else 1)
    return json.loads(run.stdout)


def timed(result):
    frames = result["frames"][1:] if len(result["frames"]) > 1 else result["frames"]
    return frames


def mean(frames, get):
    return sum(get(f) for f in frames) / len(frames)


def objects_of(f, key):
    return f["objects"][key] if "objects" in f else 0


def frame_numbers(result):
    fr = timed(result)
    return {
        "total": mean(fr, lambda f: f["ms"]["total"]),
        "pass1": mean(fr, lambda f: f["ms"]["pass1"]),
        "hiz": mean(fr, lambda f: f["ms"]["hiz"]),
        "cull": mean(fr, lambda f: f["ms"]["cull"]),
        "pass2": mean(fr, lambda f: f["ms"]["pass2"]),
        "skipped": mean(fr, lambda f: objects_of(f, "patches_culled")),
        "pass_culled": mean(fr, lambda f: f["frustum_culled"] + f["backpatch_culled"] + f["occlusion_culled"]),
        "drawn": mean(fr, lambda f: f["pass1_drawn"] + f["pass2_drawn"]),
        "triangles": mean(fr, lambda f: objects_of(f, "triangles_culled")),
        "objects": mean(fr, lambda f: objects_of(f, "frustum_culled") + objects_of(f, "backface_culled")),
        "backface_patches": mean(fr, lambda f: objects_of(f, "backface_patches_culled")),
        "false_culls": result["false_culls"],
    }


def spread(values):
    return (max(values) - min(values)) / statistics.median(values)


def ratio_text(values):
    return f"{statistics.median(values):.2f} ({min(values):.2f}..{max(values):.2f})"


def frame_time_table():
    runs = {m: [] for m in MODES}
    loads = []
    head = None
    for r in range(ROUNDS):
        loads.append(load())
        order = MODES[r % len(MODES):] + MODES[:r % len(MODES)]
        for m in order:
            result = render(["--objects", m, "--cull", "all", "--tess", str(TESS)])
            head = head or result
            runs[m].append(frame_numbers(result))
        print(f"round {r + 1}/{ROUNDS} done (order {', '.join(order)}), load {load()}", file=sys.stderr)
    loads.append(load())
    print(f"## Frame time with and without the object level: render {SCENE} --cull all --tess {TESS} "
          f"--frames {FRAMES} --json")
    print(f"renderer: {head['renderer']}; {head['patches']} patches, {head['environment_objects']} environment "
          f"objects, {head['size'][0]}x{head['size'][1]}; {ROUNDS} rounds, frames 1..{FRAMES - 1} timed; "
          f"load average (1/5/15 min) before each round and at the end: {' | '.join(loads)}")
    print()
    print("| --objects | frame (ms, median of rounds) | x none (median, min..max) | pass1 | hiz | cull | pass2 "
          "| patches skipped | culled by the passes | drawn | triangles culled | objects culled | spread |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for m in MODES:
        rs = runs[m]
        med = lambda k: statistics.median(x[k] for x in rs)
        ratios = [rs[i]["total"] / runs["none"][i]["total"] for i in range(ROUNDS)]
        print(f"| {m} | {med('total'):.1f} | {ratio_text(ratios)} | {med('pass1'):.1f} | {med('hiz'):.1f} | "
              f"{med('cull'):.1f} | {med('pass2'):.1f} | {med('skipped'):.0f} | {med('pass_culled'):.0f} | "
              f"{med('drawn'):.0f} | {med('triangles'):.0f} | {med('objects'):.1f} | "
              f"{100 * spread([x['total'] for x in rs]):.0f}% |")
    print()
    print("per-round frame times (ms): " + "; ".join(
        f"{m}: " + ", ".join(f"{x['total']:.1f}" for x in runs[m]) for m in MODES))
    bf = statistics.median(x["backface_patches"] for x in runs["bvh+backface"])
    print(f"bvh+backface: {bf:.0f} of its skipped patches per frame are in back-facing patch clusters")
    print("false_culls: not checked here (no --verify; tests/gl and `render city --verify` check them)")
    print()


def variant_table():
    print(f"## Frustum-test variants: render {SCENE} --cull none --tess 1 --frames {FRAMES} --json "
          f"(per frame, frames 1..{FRAMES - 1}), load {load()}")
    print()
    print("| variant | objects | plane tests | plane tests per object | BVH nodes visited | objects culled "
          "| meta-BV rejects |")
    print("|---|---|---|---|---|---|---|")
    for name, args in VARIANTS:
        fr = timed(render(args + ["--cull", "none", "--tess", "1"]))
        total = mean(fr, lambda f: f["objects"]["total"])
        planes = mean(fr, lambda f: f["objects"]["plane_tests"])
        print(f"| {name} | {total:.0f} | {planes:.1f} | {planes / total:.2f} | "
              f"{mean(fr, lambda f: f['objects']['bvh_nodes_visited']):.1f} | "
              f"{mean(fr, lambda f: f['objects']['frustum_culled']):.1f} | "
              f"{mean(fr, lambda f: f['objects']['meta_rejected']):.1f} |")
    print()


def main():
    if not os.access(CLI, os.X_OK):
        fail(f"BUILD_DIR: {CLI} is not an executable (build the patchcull_cli target)")
    variant_table()
    frame_time_table()
    print(f"end load {load()}")


if __name__ == "__main__":
    main()
