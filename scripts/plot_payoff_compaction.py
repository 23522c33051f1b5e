#!/usr/bin/env python3
"""The payoff of compaction: Niessner & Loop, "Patch-Based Occlusion Culling for Hardware
Tessellation", Fig. 9 left, with `--draw flags` and `--draw indirect` side by side.

Usage: python3 scripts/plot_payoff_compaction.py [DATA_DIR] [--out OUT_DIR]
       (defaults: docs/figures/data/payoff_compaction and docs/figures)

DATA_DIR holds what scripts/payoff_compaction.sh writes: roundR/SCENE/levelL_none.json,
levelL_all_flags.json, levelL_all_indirect.json, levelL_auto_flags.json, levelL_auto_indirect.json
(`patchcull render SCENE --tess L --frames N --json --cull ... --draw ...`). Prints the tables of
docs/PERFORMANCE.md ("Compaction's payoff": every value the median over the rounds of that round's
value, x with min..max) and draws payoff_compaction.png (frame time and break-even cull rate
against the level, per scene).

Per level and draw mode, from the mean over frames 1..N-1 (frame 0 compiles the programs), n the
scene's patches, per patch in microseconds:
  RT  = ms.pass1 / n of the `none` run (its one pass draws every patch),
  RT0 = (ms.pass2 - pass2_drawn * RT) / (n - pass2_drawn) of the `all` run: what pass 2 costs per
        patch it does not draw (flags: issued and dropped with level 0 in the TCS; indirect: never
        issued, so what remains is the pass's fixed cost and the compaction dispatch spread over n),
  CT  = (ms.cull + ms.hiz) / n of the `all` run (the cull passes and the Hi-Z build),
  x   = (max(RT0, 0) + CT) / (RT - max(RT0, 0)), the break-even cull rate (RT0 clamped at 0 as
        --cull auto clamps its estimate: a negative residual is noise);
  RT0 pair = (ms.pass2 of all flags - ms.pass2 of all indirect) / (n - pass2_drawn): the same
        frames (the decisions do not depend on the draw mode) drawn both ways, a check of
        RT0 flags - RT0 indirect that does not use RT;
  auto x: the median of `auto_objects[].break_even` over the `auto` run's frames 5..N-1 (after its
        bootstrap: frames 0..2 cull every object, 3..4 none) and objects; "objects culled by auto" and
        "auto / none, frames 5..N-1" over the same frames.
Bad input: one line naming the file, exit status 2 (as scripts/plot_figures.py).
"""
import math
import os
import statistics
import sys

sys.dont_write_bytecode = True  # no scripts/__pycache__ in the working tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_figures  # noqa: E402
from plot_figures import InputError, ROOT, fail, field, load_json, log_axes, save, timed_frames  # noqa: E402

PROG = "plot_payoff_compaction.py"
plot_figures.PROG = PROG  # fail()'s prefix
SCENES = [("default", "default scene"), ("city", "city")]
DRAWS = ("flags", "indirect")
# --cull auto culls every object in frames 0..2 (compilation, then CullAutoPolicy::Config::cost_frames
# = 2 frames that measure the costs), then frames 3 and 4 cull nothing (Config::measure_frames: one
# pass each, the draw cost per patch): its own decisions start at frame 5.
BOOTSTRAP = 5


def frame_mean(path, frames, get):
    return statistics.mean(get(f) for f in frames)


def load_scene(directory):
    """level -> dict of the derived values; raises InputError."""
    levels = sorted({int(name[5:].split("_")[0]) for name in os.listdir(directory)
                     if name.startswith("level") and name.endswith(".json") and name[5:].split("_")[0].isdigit()})
    if not levels:
        raise InputError(directory, "holds no levelL_*.json file (scripts/payoff_compaction.sh writes them)")
    rows = {}
    for level in levels:
        base = os.path.join(directory, f"level{level}")
        row = {}
        path = base + "_none.json"
        r = load_json(path)
        n = field(path, r, "patches", int)
        fr = timed_frames(path, r)
        row["n"] = n
        row["none_ms"] = frame_mean(path, fr, lambda f: field(path, field(path, f, "ms", dict), "total", float))
        post = fr[BOOTSTRAP - 1:] or fr
        row["none_post_ms"] = frame_mean(path, post, lambda f: field(path, field(path, f, "ms", dict), "total", float))
        rt = frame_mean(path, fr, lambda f: field(path, field(path, f, "ms", dict), "pass1", float)) / n
        row["RT"] = rt
        for draw in DRAWS:
            path = f"{base}_all_{draw}.json"
            r = load_json(path)
            fr = timed_frames(path, r)

            def ms(f, key, path=path):
                return field(path, field(path, f, "ms", dict), key, float)
            row[f"all_{draw}_ms"] = frame_mean(path, fr, lambda f: ms(f, "total"))
            row[f"RT0_{draw}"] = frame_mean(
                path, fr, lambda f: (ms(f, "pass2") - field(path, f, "pass2_drawn", int) * rt)
                / (n - field(path, f, "pass2_drawn", int)))
            row[f"CT_{draw}"] = frame_mean(path, fr, lambda f: (ms(f, "cull") + ms(f, "hiz")) / n)
            row[f"passes_{draw}"] = frame_mean(path, fr, lambda f: ms(f, "pass1") + ms(f, "pass2"))
            row[f"undrawn_{draw}"] = frame_mean(
                path, fr, lambda f: 2 * n - field(path, f, "pass1_drawn", int) - field(path, f, "pass2_drawn", int))
            row[f"submitted_{draw}"] = frame_mean(
                path, fr, lambda f: sum(field(path, field(path, f, "submitted", dict), k, int) for k in ("pass1", "pass2")))
            row["culled"] = frame_mean(path, fr, lambda f: sum(
                field(path, f, k, int) for k in ("frustum_culled", "backpatch_culled", "occlusion_culled")) / n)
            row[f"pass2_{draw}"] = frame_mean(path, fr, lambda f: ms(f, "pass2"))
            row[f"undrawn2_{draw}"] = frame_mean(path, fr, lambda f: n - field(path, f, "pass2_drawn", int))
            rt0, ct = max(row[f"RT0_{draw}"], 0.0), row[f"CT_{draw}"]
            row[f"x_{draw}"] = (rt0 + ct) / (rt - rt0) if rt > rt0 else math.inf
            path = f"{base}_auto_{draw}.json"
            r = load_json(path)
            fr = timed_frames(path, r)
            row[f"auto_{draw}_ms"] = frame_mean(path, fr, lambda f: field(path, field(path, f, "ms", dict), "total", float))
            post = fr[BOOTSTRAP - 1:] or fr
            row[f"auto_post_{draw}_ms"] = frame_mean(
                path, post, lambda f: field(path, field(path, f, "ms", dict), "total", float))
            xs, on = [], []
            for f in post:
                objs = field(path, f, "auto_objects", list)
                on.append(sum(1 for o in objs if isinstance(o, dict) and o.get("culling") == "on"))
                for o in objs:
                    x = o.get("break_even") if isinstance(o, dict) else None
                    if isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x):
                        xs.append(x)
            row[f"auto_x_{draw}"] = xs
            row[f"auto_on_{draw}"] = statistics.mean(on)
            row["objects"] = len(objs)
        # The pair check: pass 2 of the same frames, flags against indirect, per patch not drawn.
        row["RT0_pair"] = (row["pass2_flags"] - row["pass2_indirect"]) / row["undrawn2_flags"]
        rows[level] = row
    return rows


def med(xs):
    return statistics.median(xs) if xs else math.nan


def load_rounds(data_dir, scene):
    """[rows of each round] for a scene; raises InputError."""
    if not os.path.isdir(data_dir):
        raise InputError(data_dir, "no such directory (scripts/payoff_compaction.sh writes it)")
    rounds = sorted(d for d in os.listdir(data_dir) if d.startswith("round"))
    if not rounds:
        raise InputError(data_dir, "holds no roundR directory (scripts/payoff_compaction.sh writes them)")
    out = []
    for r in rounds:
        directory = os.path.join(data_dir, r, scene)
        if not os.path.isdir(directory):
            raise InputError(directory, "no such directory (scripts/payoff_compaction.sh writes it)")
        out.append(load_scene(directory))
    return out


def combine(rounds):
    """level -> {key: median over the rounds, key + '_range': (min, max)}; the ratios per round first."""
    combined = {}
    for level in sorted(set.intersection(*(set(r) for r in rounds))):
        per = [r[level] for r in rounds]
        for row in per:
            for key in ("all_flags", "all_indirect", "auto_flags", "auto_indirect"):
                row[key + "_ratio"] = row[key + "_ms"] / row["none_ms"]
            for draw in DRAWS:
                row[f"auto_post_{draw}_ratio"] = row[f"auto_post_{draw}_ms"] / row["none_post_ms"]
            row["indirect_over_flags"] = row["all_indirect_ms"] / row["all_flags_ms"]
            row["x_ratio"] = row["x_indirect"] / row["x_flags"]
            for draw in DRAWS:
                row[f"auto_xmed_{draw}"] = med(row[f"auto_x_{draw}"])
        c = {"rounds": len(per)}
        for key, value in per[0].items():
            if isinstance(value, (int, float)):
                values = [row[key] for row in per]
                c[key] = statistics.median(values)
                c[key + "_range"] = (min(values), max(values))
            else:
                c[key] = [x for row in per for x in row[key]]
        combined[level] = c
    return combined


def us(v):
    return f"{1000 * v:.2f}"


def rng(r, key, fmt):
    lo, hi = r[key + "_range"]
    return f"{format(r[key], fmt)} ({format(lo, fmt)}..{format(hi, fmt)})"


def print_table(scene, rows):
    first = rows[min(rows)]
    print(f"\n{scene}: {first['n']} patches, {first['objects']} objects, medians over {first['rounds']} rounds"
          " (min..max); RT, RT0, CT in us per patch")
    print("| level | culled | none (ms) | all / none, flags | all / none, indirect | all indirect / all flags "
          "| auto / none, flags | auto / none, indirect | the same, frames 5..7: flags / indirect "
          "| objects culled by auto, frames 5..7: flags / indirect |")
    print("|" + "---|" * 10)
    for level, r in sorted(rows.items()):
        print(f"| {level} | {100 * r['culled']:.1f}% | {r['none_ms']:.1f} | {r['all_flags_ratio']:.2f} | "
              f"{r['all_indirect_ratio']:.2f} | {rng(r, 'indirect_over_flags', '.2f')} | {r['auto_flags_ratio']:.2f} | "
              f"{r['auto_indirect_ratio']:.2f} | {r['auto_post_flags_ratio']:.2f} / {r['auto_post_indirect_ratio']:.2f} | "
              f"{r['auto_on_flags']:.1f} / {r['auto_on_indirect']:.1f} |")
    print()
    print("| level | RT | RT0 flags | RT0 indirect | RT0 flags - indirect (pass-2 pair) | CT flags | CT indirect "
          "| x flags | x indirect | x indirect / flags | auto's x, flags | auto's x, indirect |")
    print("|" + "---|" * 12)
    for level, r in sorted(rows.items()):
        print(f"| {level} | {us(r['RT'])} | {us(r['RT0_flags'])} | {us(r['RT0_indirect'])} | {us(r['RT0_pair'])} | "
              f"{us(r['CT_flags'])} | {us(r['CT_indirect'])} | {rng(r, 'x_flags', '.3f')} | "
              f"{rng(r, 'x_indirect', '.3f')} | **{rng(r, 'x_ratio', '.2f')}** | "
              f"{med(r['auto_x_flags']):.3f} | {med(r['auto_x_indirect']):.3f} |")


def plot(plt, data, out):
    fig, axes = plt.subplots(2, 2, figsize=(8, 6.5), dpi=100)
    for col, (scene, label) in enumerate(SCENES):
        rows = data[scene]
        levels = sorted(rows)
        top, bottom = axes[0][col], axes[1][col]
        for i, (key, name) in enumerate((("none_ms", "no culling"), ("all_flags_ms", "all, --draw flags"),
                                         ("all_indirect_ms", "all, --draw indirect"))):
            top.plot(levels, [rows[L][key] for L in levels], marker="o", color=f"C{i}", label=name)
        # auto after its bootstrap (its own decisions): the bootstrap's unculled frames would
        # dominate a whole-run mean at high levels.
        post = f"frames {BOOTSTRAP} on"
        for i, (key, name) in enumerate((("auto_post_flags_ms", f"auto, flags, {post}"),
                                         ("auto_post_indirect_ms", f"auto, indirect, {post}"))):
            top.plot(levels, [rows[L][key] for L in levels], marker=".", color=f"C{i + 1}", linestyle=":", label=name)
        log_axes(top, "both")
        top.set_xlabel("tessellation level")
        top.set_ylabel("frame time (ms, llvmpipe)")
        top.set_title(f"{label} ({rows[levels[0]]['n']} patches): frame time, median of {rows[levels[0]]['rounds']}",
                      fontsize=9)
        top.grid(True, which="both", alpha=0.3)
        top.legend(fontsize=7)
        for i, draw in enumerate(DRAWS):
            bottom.plot(levels, [rows[L][f"x_{draw}"] for L in levels], marker="o", color=f"C{i + 1}",
                        label=f"x = (RT0+CT)/(RT-RT0), {draw}")
            bottom.fill_between(levels, [rows[L][f"x_{draw}_range"][0] for L in levels],
                                [rows[L][f"x_{draw}_range"][1] for L in levels], color=f"C{i + 1}", alpha=0.15)
            bottom.plot(levels, [med(rows[L][f"auto_x_{draw}"]) for L in levels], marker=".", color=f"C{i + 1}",
                        linestyle=":", label=f"--cull auto's x (median), {draw}")
        bottom.plot(levels, [rows[L]["culled"] for L in levels], marker="s", color="C4", label="culled by all")
        log_axes(bottom, "x")
        shown = [v for L in levels for v in (rows[L]["x_flags_range"][1], rows[L]["x_indirect_range"][1],
                                             rows[L]["culled"]) if math.isfinite(v)]
        bottom.set_ylim(0, min(2.0, max(1.0, 1.1 * max(shown))))
        bottom.set_xlabel("tessellation level")
        bottom.set_ylabel("cull rate")
        bottom.set_title("break-even cull rate (band: min..max over rounds)", fontsize=9)
        bottom.grid(True, which="both", alpha=0.3)
        bottom.legend(fontsize=6)
    fig.suptitle("Compaction's payoff (cf. Niessner & Loop, Fig. 9 left): flags vs indirect draws", fontsize=10)
    save(fig, out, "payoff_compaction.png")


def main(argv):
    data_dir = os.path.join(ROOT, "docs", "figures", "data", "payoff_compaction")
    out = os.path.join(ROOT, "docs", "figures")
    positional = []
    i = 0
    while i < len(argv):
        if argv[i] == "--out":
            if i + 1 >= len(argv) or not argv[i + 1]:
                fail("--out: expected a directory")
            out = argv[i + 1]
            i += 2
        elif argv[i] in ("-h", "--help"):
            print(__doc__)
            return 0
        elif argv[i].startswith("-"):
            fail(f"unknown option {argv[i]!r} (usage: {PROG} [DATA_DIR] [--out OUT_DIR])")
        else:
            positional.append(argv[i])
            i += 1
    if len(positional) > 1:
        fail(f"expected at most one DATA_DIR (usage: {PROG} [DATA_DIR] [--out OUT_DIR])")
    if positional:
        data_dir = positional[0]
    if not os.path.isdir(out):
        fail(f"--out: {out}: no such directory")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        fail("matplotlib is not installed for this Python (Debian: python3-matplotlib, for /usr/bin/python3)")
    try:
        data = {}
        for scene, _ in SCENES:
            data[scene] = combine(load_rounds(data_dir, scene))
            print_table(scene, data[scene])
        plot(plt, data, out)
    except InputError as e:
        fail(str(e))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
