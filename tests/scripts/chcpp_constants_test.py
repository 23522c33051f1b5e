#!/usr/bin/env python3
"""ctest for scripts/chcpp_constants.py (docs/PERFORMANCE.md, "CHC++'s constants"): a tiny run
(city_small, 2 frames, 64x36, two c1 values, two sigma values) must give one row per value with
queries, 0 false culls, and more proxy boxes at the larger sigma (tighter volumes, more boxes);
then bad input (a list that is not one, out of range, a size, an unknown option, a CLI that is not
there), each exit status 2 and one line naming the flag or path.
Usage: chcpp_constants_test.py REPO_ROOT CLI
"""
import json
import os
import subprocess
import sys
import tempfile

ROOT, CLI = sys.argv[1], sys.argv[2]
SCRIPT = os.path.join(ROOT, "scripts", "chcpp_constants.py")
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def run(*args, cli=True):
    return subprocess.run([sys.executable, SCRIPT, *(["--cli", CLI] if cli else []), *args],
                          capture_output=True, text=True, stdin=subprocess.DEVNULL)


with tempfile.TemporaryDirectory(prefix="chcpp_constants_test_") as tmp:
    out = os.path.join(tmp, "constants.json")
    r = run("--frames", "2", "--size", "64x36", "--tess", "1", "--c1", "0,1", "--sigma", "1,4", "--json", out)
    check(r.returncode == 0, f"tiny run: exit {r.returncode}: {r.stderr.strip()}")
    if r.returncode == 0:
        with open(out) as f:
            rows = json.load(f)["rows"]
        check([(row["c1"], row["sigma"]) for row in rows] == [(0, 1.4), (1, 1.4), (0.1, 1), (0.1, 4)],
              f"rows {[(row['c1'], row['sigma']) for row in rows]}")
        for row in rows:
            check(row["queries"] > 0, f"c1 {row['c1']} sigma {row['sigma']}: no query")
            check(row["false_culls"] == 0, f"c1 {row['c1']} sigma {row['sigma']}: {row['false_culls']} false culls")
        if len(rows) == 4:
            check(rows[3]["proxy_boxes"] > rows[2]["proxy_boxes"],
                  f"sigma 4 drew {rows[3]['proxy_boxes']} boxes, sigma 1 {rows[2]['proxy_boxes']}")

for args, flag in [(["--c1", "a,b"], "--c1"), (["--sigma", "0.5"], "--sigma"), (["--size", "0x3"], "--size"),
                   (["--frames", "0"], "--frames"), (["--bogus", "1"], "--bogus")]:
    r = run(*args)
    lines = r.stderr.strip().splitlines()
    check(r.returncode == 2 and len(lines) == 1 and flag in lines[0], f"{args}: exit {r.returncode}, stderr {r.stderr!r}")
r = run("--cli", "/nonexistent/patchcull", cli=False)
check(r.returncode == 2 and "/nonexistent/patchcull" in r.stderr, f"missing cli: exit {r.returncode}, {r.stderr!r}")

for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
