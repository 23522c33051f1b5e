#!/usr/bin/env python3
"""docs/RESULTS.md's "Far from the origin" table: BigGuy translated by (t, t, t), every CPU cull
method, both schemes and view modes, cull rate and false culls per translation.

usage: scripts/far_origin_table.py PATCHCULL_BINARY [VIEWS] [OUT_DIR]
Writes the translated OBJ copies to OUT_DIR (default: a temporary directory) and prints a
Markdown table."""
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
METHODS = ["frustum", "frustum-disp", "tcone", "ncone", "ptp", "ptp-pcnt"]
TRANSLATIONS = ["0", "1e2", "1e4", "1e5", "1e6", "1e7"]


def translate(src, dst, t):
    with open(src) as f, open(dst, "w") as g:
        for line in f:
            parts = line.split()
            if parts and parts[0] == "v":
                line = "v " + " ".join([repr(float(v) + t) for v in parts[1:4]] + parts[4:]) + "\n"
            g.write(line)


def main():
    binary = sys.argv[1]
    views = sys.argv[2] if len(sys.argv) > 2 else "200"
    out_dir = sys.argv[3] if len(sys.argv) > 3 else tempfile.mkdtemp(prefix="patchcull_far_")
    model = os.path.join(ROOT, "data", "models", "bigguy.obj")
    paths = {}
    for t in TRANSLATIONS:
        paths[t] = os.path.join(out_dir, "bigguy_%s.obj" % t)
        translate(model, paths[t], float(t))
    print("| scheme | views | translation | " + " | ".join(METHODS) + " |")
    print("|---|---|---|" + "---|" * len(METHODS))
    for scheme in ["acc", "osd"]:
        for mode in ["free", "contain"]:
            for t in TRANSLATIONS:
                out = subprocess.run([binary, "cull", paths[t], "--scheme", scheme, "--view-mode", mode,
                                      "--views", views, "--methods", ",".join(METHODS), "--json"],
                                     check=True, capture_output=True, text=True).stdout
                m = json.loads(out)["methods"]
                cells = ["%.2f (%d)" % (100 * m[k]["cull_rate"], m[k]["false_culls"]) for k in METHODS]
                print("| %s | %s | %s | %s |" % (scheme, mode, t, " | ".join(cells)))


if __name__ == "__main__":
    main()
