#!/usr/bin/env python3
"""Draws the figures of docs/PERFORMANCE.md and docs/RESULTS.md from the CLI's JSON output.

Usage: python3 scripts/plot_figures.py [DATA_DIR] [--out OUT_DIR]
       (defaults: docs/figures/data and docs/figures, relative to the repository)

DATA_DIR holds what scripts/make_figures.sh writes (it runs the commands; each file is one
command's stdout):
  cull_pass/*.json       `patchcull render MODEL --split S --frames 4 --tess 1 --size 256x256
                         --cull occlusion --json`, and the same with `--cull all --backpatch
                         tcone|ncone|ptp`: cull-pass time against patch count -> cull_pass_vs_patches.png
                         (Niessner & Loop, "Patch-Based Occlusion Culling for Hardware
                         Tessellation", Fig. 7 left)
  tess_levels/*.json     `patchcull render default --cull none|all|auto --tess L --frames N --json`:
                         frame time and the break-even cull rate against the tessellation level
                         -> frame_time_vs_tess.png (the same paper, Fig. 9 left)
  backpatch_table/*.json `patchcull cull MODEL [--split 1] --methods tcone,ncone,ptp --views V --json`
                         -> table1_backpatch.png, beside Table 1 of Loop, Niessner & Eisenacher,
                         "Effective Back-Patch Culling for Hardware Tessellation"
  displaced_table/*.json `patchcull eval displaced MODEL [--split 1] --views V --json`
                         -> table1_displaced.png, beside Table 1 of Niessner & Loop
  temporal.json          `patchcull eval temporal MODEL --speeds LIST --frames N --json`
                         -> temporal_coherence.png, beside Fig. 9 right of Niessner & Loop
  fig7/*.json            scripts/fig7_sweep.py: `patchcull render monsterfrog.obj --split S --cull
                         occlusion` undisplaced (nodisp) and displaced with --bound caf --cone
                         full|acon|con (and oobb_acon): cull-pass time against patch count
                         -> fig7_cull_pass_displaced.png (Niessner & Loop, Fig. 7 left)
The papers' values drawn beside ours are typed in below from the papers' tables and text.

Bad input (a missing file or directory, a file that is not JSON or not the shape its command
prints) gives one line naming the file on stderr and exit status 2. The PNGs are 800x500 pixels
(matplotlib's Agg backend: no display needed).
"""
import glob
import json
import math
import os
import statistics
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROG = "plot_figures.py"

# Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for Hardware Tessellation", Table 1:
# average cull rates over 10k random views (GTX 480). Their BigGuy has 3570 patches, ours 1450.
PAPER_BACKPATCH = [
    ("BigGuy", 3570, {"tcone": 0.35, "ncone": 0.45, "ptp": 0.48}),
    ("MonsterFrog", 5168, {"tcone": 0.37, "ncone": 0.44, "ptp": 0.48}),
    ("Killeroo", 11532, {"tcone": 0.33, "ncone": 0.40, "ptp": 0.45}),
]
# Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation", Table 1: average
# cull rates of displaced models (Frog = MonsterFrog, Frog^2 after one 1-to-4 split).
PAPER_DISPLACED = [
    ("Frog", 1292, {("oobb", "full"): 0.105, ("oobb", "acon"): 0.121, ("oobb", "con"): 0.140,
                    ("caf", "full"): 0.144, ("caf", "acon"): 0.170, ("caf", "con"): 0.184}),
    ("Frog\u00b2", 5168, {("oobb", "full"): 0.171, ("oobb", "acon"): 0.251, ("oobb", "con"): 0.264,
                          ("caf", "full"): 0.228, ("caf", "acon"): 0.294, ("caf", "con"): 0.309}),
]
# The same paper, §6.3 and Fig. 9: BigGuy rotating, 25.5% culled at rest, 20.4% at 10 degrees per
# frame; culling pays above a tess factor of 4, at a cull rate of 35.8% (ACoN kernel).
PAPER_TEMPORAL = [(0, 0.255), (10, 0.204)]
PAPER_BREAK_EVEN = (4, 0.358)

BOUNDS = [("oobb", "full"), ("oobb", "acon"), ("oobb", "con"), ("caf", "full"), ("caf", "acon"), ("caf", "con")]
BACKPATCH = ["tcone", "ncone", "ptp"]


class InputError(Exception):
    """One line naming the file: the script's only error output."""

    def __init__(self, path, message):
        super().__init__(f"{path}: {message}")


def fail(message):
    # Printable and bounded, whatever a path holds.
    text = message.encode("ascii", "backslashreplace").decode("ascii").replace("\n", "\\n")
    print(f"{PROG}: error: {text[:500]}", file=sys.stderr)
    sys.exit(2)


def load_json(path):
    if not os.path.isfile(path):
        raise InputError(path, "no such file (scripts/make_figures.sh writes it)")
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise InputError(path, f"not a JSON file ({str(e).splitlines()[0]})")


def field(path, obj, key, kind):
    """obj[key], which must be of kind (a type or tuple of types; numbers also finite)."""
    if not isinstance(obj, dict) or key not in obj:
        raise InputError(path, f"expected a key '{key}'")
    value = obj[key]
    numeric = kind in (float, int) or kind == (int, float)
    if numeric:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise InputError(path, f"'{key}' is not a finite number")
        return value
    if not isinstance(value, kind):
        raise InputError(path, f"'{key}' is not a {kind.__name__}")
    return value


def json_files(directory):
    if not os.path.isdir(directory):
        raise InputError(directory, "no such directory (scripts/make_figures.sh writes it)")
    files = sorted(glob.glob(os.path.join(directory, "*.json")))
    if not files:
        raise InputError(directory, "holds no .json file")
    return files


def model_name(path_or_name):
    name = os.path.splitext(os.path.basename(path_or_name))[0]
    return {"bigguy": "BigGuy", "monsterfrog": "MonsterFrog"}.get(name, name)


def model_label(path_or_name, patches):
    return f"{model_name(path_or_name)} ({patches})"


def timed_frames(path, result):
    frames = field(path, result, "frames", list)
    if not frames:
        raise InputError(path, "'frames' is empty")
    return frames[1:] or frames  # frame 0 compiles the programs and primes the statuses


def mean_ms(path, result, key):
    frames = timed_frames(path, result)
    return statistics.mean(field(path, field(path, f, "ms", dict), key, float) for f in frames)


def plural(n, word):
    return f"{n} {word}" + ("" if n == 1 else "s")


def log_axes(ax, which):
    """Log scale on x (base 2: levels, patch counts) and/or y, with plain numbers as labels."""
    from matplotlib.ticker import FuncFormatter
    plain = FuncFormatter(lambda v, _: f"{v:g}")
    if which in ("x", "both"):
        ax.set_xscale("log", base=2)
        ax.xaxis.set_major_formatter(plain)
    if which in ("y", "both"):
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(plain)
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))


# ---- the figures ------------------------------------------------------------------------------

def plot_cull_pass(plt, data, out):
    """Cull-pass time (ms) against patch count, per chain of passes."""
    series = {}  # chain -> [(patches, ms, model)]
    for path in json_files(os.path.join(data, "cull_pass")):
        r = load_json(path)
        cull = field(path, r, "cull", str)
        if cull == "occlusion":
            chain = "occlusion"
        elif cull == "all":
            chain = "frustum + " + field(path, r, "backpatch", str) + " + occlusion"
        else:
            raise InputError(path, f"'cull' is '{cull}', expected occlusion or all")
        patches = field(path, r, "patches", int)
        series.setdefault(chain, []).append((patches, mean_ms(path, r, "cull"), field(path, r, "model", str)))
    fig, ax = plt.subplots(figsize=(8, 5), dpi=100)
    order = ["occlusion"] + [f"frustum + {m} + occlusion" for m in BACKPATCH]
    chains = [c for c in order if c in series] + sorted(set(series) - set(order))
    models = sorted({m for points in series.values() for _, _, m in points})
    for c, chain in enumerate(chains):
        for k, model in enumerate(models):
            pts = sorted((p, ms) for p, ms, m in series[chain] if m == model)
            if pts:
                ax.plot([p for p, _ in pts], [ms for _, ms in pts], marker="osD^v"[k % 5], color=f"C{c}",
                        linestyle=["-", "--", ":", "-."][k % 4],
                        label=f"{chain}: {model_name(model)}")
    log_axes(ax, "both")
    ax.set_xlabel("patches (each model split 0, 1, 2 times)")
    ax.set_ylabel("cull passes per frame (ms, llvmpipe)")
    ax.set_title("Cull-pass time against patch count (cf. Niessner & Loop, Fig. 7 left)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    save(fig, out, "cull_pass_vs_patches.png")


def plot_tess_levels(plt, data, out):
    """Frame time of none/all/auto and the break-even cull rate against the tessellation level."""
    times = {}       # (mode, level) -> ms
    culled = {}      # level -> fraction of patches culled by `all`
    break_even = {}  # level -> [x of each object in auto's last frames]
    for path in json_files(os.path.join(data, "tess_levels")):
        r = load_json(path)
        mode = field(path, r, "cull", str)
        level = field(path, r, "tess", int)
        if mode not in ("none", "all", "auto"):
            raise InputError(path, f"'cull' is '{mode}', expected none, all or auto")
        times[(mode, level)] = mean_ms(path, r, "total")
        frames = timed_frames(path, r)
        patches = field(path, r, "patches", int)
        if mode == "all":
            culled[level] = statistics.mean(
                sum(field(path, f, k, int) for k in ("frustum_culled", "backpatch_culled", "occlusion_culled"))
                / patches for f in frames)
        if mode == "auto":
            xs = []
            for f in frames:
                for o in field(path, f, "auto_objects", list):
                    x = o.get("break_even") if isinstance(o, dict) else None
                    if isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x):
                        xs.append(x)
            break_even[level] = xs
    fig, (left, right) = plt.subplots(1, 2, figsize=(8, 5), dpi=100)
    for i, mode in enumerate(("none", "all", "auto")):
        levels = sorted(L for m, L in times if m == mode)
        if levels:
            left.plot(levels, [times[(mode, L)] for L in levels], marker="o", color=f"C{i}",
                      label={"none": "no culling", "all": "culling (all, tcone)", "auto": "--cull auto"}[mode])
    log_axes(left, "both")
    left.set_xlabel("tessellation level")
    left.set_ylabel("frame time (ms, llvmpipe)")
    left.set_title("Default scene, frame time", fontsize=10)
    left.grid(True, which="both", alpha=0.3)
    left.legend(fontsize=8)
    levels = sorted(L for L in break_even if break_even[L])
    if levels:
        medians = [statistics.median(break_even[L]) for L in levels]
        right.plot(levels, medians, marker="o", color="C3", label="break-even x (auto's measure, median)")
        right.fill_between(levels, [min(break_even[L]) for L in levels], [max(break_even[L]) for L in levels],
                           color="C3", alpha=0.15, label="break-even, min..max over frames and objects")
    if culled:
        cl = sorted(culled)
        right.plot(cl, [culled[L] for L in cl], marker="s", color="C1", label="culled by all (fraction)")
    right.plot([PAPER_BREAK_EVEN[0]], [PAPER_BREAK_EVEN[1]], marker="*", markersize=12, color="k", linestyle="none",
               label="paper: pays above level 4 at 35.8%")
    log_axes(right, "x")
    shown = [x for L in levels for x in break_even[L]] + list(culled.values()) + [PAPER_BREAK_EVEN[1]]
    right.set_ylim(0, min(2.5, max(1.0, 1.1 * max(shown))))  # x > 1: culling cannot pay at that level
    right.set_xlabel("tessellation level")
    right.set_ylabel("cull rate")
    right.set_title("Culling pays where culled > break-even (cf. Fig. 9 left)", fontsize=9)
    right.grid(True, which="both", alpha=0.3)
    right.legend(fontsize=7)
    fig.suptitle("Frame time and break-even against the tessellation level (Niessner & Loop, Fig. 9)", fontsize=10)
    save(fig, out, "frame_time_vs_tess.png")


def grouped_bars(ax, groups, keys, key_labels):
    """groups: [(label, {key: rate}, is_paper)]: one cluster of bars per group."""
    width = 0.8 / len(keys)
    for k, key in enumerate(keys):
        xs = [g + (k - (len(keys) - 1) / 2) * width for g in range(len(groups))]
        heights = [100 * values[key] for _, values, _ in groups]
        bars = ax.bar(xs, heights, width, color=f"C{k}", label=key_labels[k])
        for bar, (_, _, paper) in zip(bars, groups):
            if paper:
                bar.set_hatch("//")
                bar.set_edgecolor("white")
    ax.set_xticks(range(len(groups)))
    ax.set_xticklabels([label for label, _, _ in groups], fontsize=7)
    ax.set_ylabel("cull rate (%)")
    ax.grid(True, axis="y", alpha=0.3)
    top = max(100 * v for _, values, _ in groups for v in values.values())
    ax.set_ylim(0, top * 1.3)  # room for the legend above the bars
    from matplotlib.patches import Patch
    handles = [Patch(facecolor=f"C{k}", label=key_labels[k]) for k in range(len(keys))]
    handles.append(Patch(facecolor="grey", hatch="//", edgecolor="white", label="the paper's value"))
    ax.legend(handles=handles, fontsize=7, ncol=min(len(handles), 4), loc="upper left")


def plot_backpatch_table(plt, data, out):
    ours = []
    for path in json_files(os.path.join(data, "backpatch_table")):
        r = load_json(path)
        methods = field(path, r, "methods", dict)
        rates = {m: field(path, field(path, methods, m, dict), "cull_rate", float) for m in BACKPATCH}
        views = field(path, r, "views", int)
        ours.append((field(path, r, "model", str), field(path, r, "patches", int), views, rates))
    groups = []
    for name, patches, rates in PAPER_BACKPATCH:
        groups.append((f"paper:\n{name} ({patches})", rates, True))
        for model, p, views, r in sorted(ours, key=lambda o: o[1]):
            if name.lower() in os.path.basename(model).lower():
                groups.append((f"ours:\n{model_label(model, p)}\n{plural(views, 'view')}", r, False))
    fig, ax = plt.subplots(figsize=(8, 5), dpi=100)
    grouped_bars(ax, groups, BACKPATCH, ["TCONE", "NCONE", "PTP"])
    ax.set_title("Back-patch cull rates, ours beside Table 1 of Loop, Niessner & Eisenacher,\n"
                 "\"Effective Back-Patch Culling for Hardware Tessellation\" (random whole-object views)", fontsize=9)
    save(fig, out, "table1_backpatch.png")


def plot_displaced_table(plt, data, out):
    ours = []
    for path in json_files(os.path.join(data, "displaced_table")):
        r = load_json(path)
        rates = {}
        for row in field(path, r, "rows", list):
            key = (field(path, row, "bound", str), field(path, row, "cone", str))
            rates[key] = field(path, row, "cull_rate", float)
        missing = [f"{b}/{c}" for b, c in BOUNDS if (b, c) not in rates]
        if missing:
            raise InputError(path, "'rows' lacks " + ", ".join(missing))
        ours.append((field(path, r, "patches", int), field(path, r, "views", int), rates))
    groups = []
    for name, patches, rates in PAPER_DISPLACED:
        groups.append((f"paper:\n{name} ({patches})", rates, True))
        for p, views, r in ours:
            if p == patches:
                groups.append((f"ours:\nMonsterFrog ({p})\n{plural(views, 'view')}", r, False))
    for p, views, r in ours:  # models of other sizes, after the paper's
        if p not in [patches for _, patches, _ in PAPER_DISPLACED]:
            groups.append((f"ours:\n({p} patches)\n{plural(views, 'view')}", r, False))
    fig, ax = plt.subplots(figsize=(8, 5), dpi=100)
    cone_names = {"full": "Full", "acon": "ACoN", "con": "CoN"}
    grouped_bars(ax, groups, BOUNDS, [f"{b.upper()} {cone_names[c]}" for b, c in BOUNDS])
    ax.set_title("Displaced-patch cull rates, ours beside Table 1 of Niessner & Loop,\n"
                 "\"Patch-Based Occlusion Culling for Hardware Tessellation\" (frustum + occlusion)", fontsize=9)
    save(fig, out, "table1_displaced.png")


def plot_temporal(plt, data, out):
    path = os.path.join(data, "temporal.json")
    r = load_json(path)
    rows = field(path, r, "speeds", list)
    if not rows:
        raise InputError(path, "'speeds' is empty")
    speeds = [field(path, row, "degrees_per_frame", float) for row in rows]
    moving = [100 * field(path, row, "occluded_fraction", float) for row in rows]
    converged = [100 * field(path, row, "converged_occluded_fraction", float) for row in rows]
    fig, ax = plt.subplots(figsize=(8, 5), dpi=100)
    ax.plot(speeds, moving, marker="o", color="C0", label="ours: running pipeline (moving camera)")
    ax.plot(speeds, converged, marker="s", color="C1", linestyle="--", label="ours: converged, same views")
    ax.plot([s for s, _ in PAPER_TEMPORAL], [100 * v for _, v in PAPER_TEMPORAL], marker="*", markersize=12,
            color="k", linestyle=":", label="paper: BigGuy rotating, 25.5% at rest, 20.4% at 10 deg/frame")
    ax.set_xscale("symlog", linthresh=1)
    ax.set_xticks(speeds)
    ax.set_xticklabels([f"{v:g}" for v in speeds])
    ax.minorticks_off()
    ax.set_xlabel("rotation speed (degrees per frame)")
    ax.set_ylabel("occluded patches (%)")
    ax.set_ylim(bottom=0)
    ax.set_title(f"Temporal coherence: {model_label(field(path, r, 'model', str), field(path, r, 'patches', int))}, "
                 f"{field(path, r, 'frames', int)} frames per speed (cf. Niessner & Loop, Fig. 9 right)", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, out, "temporal_coherence.png")


FIG7_CURVES = [("nodisp", "NoDisp (undisplaced: frustum + Hi-Z of the control points)"),
               ("full", "Full (CAF, no cone)"), ("acon", "ACoN (CAF, approximate cone)"),
               ("con", "CoN (CAF, exact cone of normals)"), ("oobb_acon", "OOBB with ACoN (Munkberg et al.)")]


def plot_fig7(plt, data, out):
    """Cull-pass time (ms) against patch count: undisplaced and displaced kernels (Fig. 7 left)."""
    series = {}  # curve -> [(patches, ms)]
    for path in json_files(os.path.join(data, "fig7")):
        curve = os.path.basename(path).rsplit("_split", 1)[0]
        if curve not in dict(FIG7_CURVES):
            raise InputError(path, f"unknown curve '{curve}' (expected one of {', '.join(dict(FIG7_CURVES))})")
        r = load_json(path)
        displaced = field(path, r, "displaced_patches", int)
        if (curve == "nodisp") != (displaced == 0):
            raise InputError(path, f"'displaced_patches' is {displaced}, which does not fit the curve '{curve}'")
        series.setdefault(curve, []).append((field(path, r, "patches", int), mean_ms(path, r, "cull")))
    fig, ax = plt.subplots(figsize=(8, 5), dpi=100)
    for c, (curve, label) in enumerate(FIG7_CURVES):
        pts = sorted(series.get(curve, []))
        if pts:
            ax.plot([p for p, _ in pts], [ms for _, ms in pts], marker="osD^v"[c], color=f"C{c}",
                    linestyle="--" if curve == "oobb_acon" else "-", label=label)
    log_axes(ax, "both")
    ax.set_xlabel("patches (MonsterFrog split 0..3; displaced: procedural map on every patch)")
    ax.set_ylabel("cull passes per frame (ms, llvmpipe: the CPU runs the kernels)")
    ax.set_title("Cull-pass time against patch count. Niessner & Loop, Fig. 7 left (a GPU): NoDisp, Full\n"
                 "and ACoN about equal, CoN about 10x slower, OOBB kernels within 3% of CAF's", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, out, "fig7_cull_pass_displaced.png")


def save(fig, out, name):
    fig.tight_layout()
    path = os.path.join(out, name)
    try:
        fig.savefig(path)
    except OSError as e:
        raise InputError(path, f"cannot write ({e.strerror})")
    finally:
        import matplotlib.pyplot as plt
        plt.close(fig)
    print(path)


def main(argv):
    data, out = os.path.join(ROOT, "docs", "figures", "data"), os.path.join(ROOT, "docs", "figures")
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
        fail(f"expected at most one DATA_DIR, got {len(positional)} (usage: {PROG} [DATA_DIR] [--out OUT_DIR])")
    if positional:
        data = positional[0]
    if not os.path.isdir(out):
        fail(f"--out: {out}: no such directory")
    try:
        import matplotlib
        matplotlib.use("Agg")  # headless
        import matplotlib.pyplot as plt
    except ImportError:
        fail("matplotlib is not installed for this Python (Debian: python3-matplotlib, for /usr/bin/python3)")
    try:
        for plot in (plot_cull_pass, plot_tess_levels, plot_backpatch_table, plot_displaced_table, plot_temporal,
                     plot_fig7):
            plot(plt, data, out)
    except InputError as e:
        fail(str(e))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
