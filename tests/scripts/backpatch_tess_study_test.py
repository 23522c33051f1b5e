#!/usr/bin/env python3
"""ctest for scripts/backpatch_tess_study.py (docs/PERFORMANCE.md, "Back-patch culling against
the tessellation level"): a tiny run (levels 1 and 2, 64x36, two frames) must give one row per
level in which no culling culls nothing and the back-patch tests cull in the order of Loop, Niessner &
Eisenacher, "Effective Back-Patch Culling for Hardware Tessellation",
0 < TCONE <= NCONE <= PTP, with positive frame-time ratios; then bad input (a level list that is
not one, a level out of range, a size, a frame count, an unknown option, a CLI that is not there),
each exit status 2 and one line naming the flag or the path.
Usage: backpatch_tess_study_test.py REPO_ROOT CLI
"""
import json
import os
import subprocess
import sys
import tempfile

ROOT, CLI = sys.argv[1], sys.argv[2]
SCRIPT = os.path.join(ROOT, "scripts", "backpatch_tess_study.py")
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def run(*args, cli=True):
    return subprocess.run([sys.executable, SCRIPT, *(["--cli", CLI] if cli else []), *args],
                          capture_output=True, text=True, stdin=subprocess.DEVNULL)


with tempfile.TemporaryDirectory(prefix="backpatch_tess_test_") as tmp:
    out = os.path.join(tmp, "study.json")
    r = run("--levels", "1,2", "--size", "64x36", "--frames", "2", "--json", out)
    check(r.returncode == 0, f"tiny run: exit {r.returncode}: {r.stderr.strip()}")
    if r.returncode == 0:
        with open(out) as f:
            rows = json.load(f)["rows"]
        check([row["level"] for row in rows] == [1, 2], f"levels {[row['level'] for row in rows]}")
        for row in rows:
            check(row["none_culled"] == 0, f"L{row['level']}: no culling culled {row['none_culled']}")
            check(0 < row["tcone_culled"] <= row["ncone_culled"] <= row["ptp_culled"] < row["patches"],
                  f"L{row['level']}: culled tcone {row['tcone_culled']} ncone {row['ncone_culled']} "
                  f"ptp {row['ptp_culled']} of {row['patches']}")
            for mode in ("tcone", "ncone", "ptp"):
                check(row[f"{mode}_ratio"] > 0 and row[f"{mode}_cull_ms"] >= 0, f"L{row['level']} {mode}: ratio/cull ms")

for args, name, cli in ((["--levels", "two"], "--levels", True), (["--levels", "0"], "--levels", True),
                        (["--size", "64"], "--size", True), (["--frames", "1"], "--frames", True),
                        (["--bogus", "1"], "--bogus", True),
                        (["--cli", "/nonexistent/patchcull"], "/nonexistent/patchcull", False)):
    r = run(*args, cli=cli)
    lines = r.stderr.strip().splitlines()
    check(r.returncode == 2 and len(lines) == 1 and name in lines[0] and r.stdout == "",
          f"{args}: exit {r.returncode}, stderr {r.stderr!r}")

for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
