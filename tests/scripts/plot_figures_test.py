#!/usr/bin/env python3
"""ctest for scripts/plot_figures.py: draws every figure from the committed data
(docs/figures/data) into a temporary directory and checks the PNGs (signature, 800x500 pixels,
not blank); then bad input: a missing data directory, a file that is not JSON, a file of the
wrong shape, an unknown option. Each must give exit status 2 and one line naming the file or the
option. Usage: plot_figures_test.py REPO_ROOT (run with a python3 that has matplotlib).
"""
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

ROOT = sys.argv[1]
SCRIPT = os.path.join(ROOT, "scripts", "plot_figures.py")
DATA = os.path.join(ROOT, "docs", "figures", "data")
FIGURES = ["cull_pass_vs_patches.png", "frame_time_vs_tess.png", "table1_backpatch.png", "table1_displaced.png",
           "temporal_coherence.png", "fig7_cull_pass_displaced.png"]
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


def png_size_and_spread(path):
    """(width, height, distinct byte values in the first 64 KiB of decompressed pixel rows)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    width, height = struct.unpack(">II", data[16:24])
    idat, pos = b"", 8
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        if kind == b"IDAT":
            idat += data[pos + 8:pos + 8 + length]
        pos += 12 + length
    pixels = zlib.decompress(idat)
    return width, height, len(set(pixels[:65536]))


def expect_one_line_error(result, must_name, what):
    lines = result.stderr.splitlines()
    check(result.returncode == 2, f"{what}: exit status {result.returncode}, expected 2 ({result.stderr!r})")
    check(len(lines) == 1, f"{what}: {len(lines)} lines on stderr, expected 1 ({result.stderr!r})")
    check(must_name in result.stderr, f"{what}: stderr does not name {must_name!r} ({result.stderr!r})")


with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "figures")
    os.mkdir(out)
    result = run(DATA, "--out", out)
    check(result.returncode == 0, f"plot from {DATA}: exit status {result.returncode}: {result.stderr}")
    for name in FIGURES:
        path = os.path.join(out, name)
        if not os.path.isfile(path):
            failures.append(f"{name} not written")
            continue
        info = png_size_and_spread(path)
        check(info is not None, f"{name} is not a PNG")
        if info:
            check(info[:2] == (800, 500), f"{name} is {info[0]}x{info[1]}, expected 800x500")
            check(info[2] > 8, f"{name} looks blank ({info[2]} distinct bytes)")

    # Bad input: each one line naming what is wrong, exit status 2.
    expect_one_line_error(run(os.path.join(tmp, "nowhere"), "--out", out), "nowhere", "missing data directory")
    broken = os.path.join(tmp, "broken")
    shutil.copytree(DATA, broken)
    with open(os.path.join(broken, "temporal.json"), "w") as f:
        f.write('{"model": "bigguy", "speeds": [')
    expect_one_line_error(run(broken, "--out", out), "temporal.json", "truncated JSON")
    with open(os.path.join(broken, "temporal.json"), "w") as f:
        f.write('{"model": "bigguy", "patches": 1450, "frames": 12, "speeds": [{"degrees_per_frame": 0}]}')
    expect_one_line_error(run(broken, "--out", out), "temporal.json", "row without occluded_fraction")
    victim = sorted(os.listdir(os.path.join(broken, "backpatch_table")))[0]
    with open(os.path.join(broken, "backpatch_table", victim), "w") as f:
        f.write('{"model": "x", "patches": 1, "views": 1, "methods": {"tcone": {"cull_rate": "high"}}}')
    expect_one_line_error(run(broken, "--out", out), victim, "cull_rate not a number")
    fig7 = os.path.join(tmp, "fig7_broken")  # fig7 is drawn last: the other files must be good
    shutil.copytree(DATA, fig7)
    shutil.copy(os.path.join(fig7, "fig7", "acon_split0.json"), os.path.join(fig7, "fig7", "nodisp_split9.json"))
    expect_one_line_error(run(fig7, "--out", out), "nodisp_split9.json", "displaced patches in the NoDisp curve")
    # scripts/fig7_sweep.py's bad arguments (no CLI is run: the checks come first).
    sweep = os.path.join(ROOT, "scripts", "fig7_sweep.py")
    def run_sweep(*args):
        return subprocess.run([sys.executable, sweep, *args], capture_output=True, text=True)
    expect_one_line_error(run_sweep(os.path.join(tmp, "no_build")), "BUILD_DIR", "fig7_sweep.py without a CLI")
    fake_build = os.path.join(tmp, "fake_build")
    os.mkdir(fake_build)
    with open(os.path.join(fake_build, "patchcull"), "w") as f:
        f.write("#!/bin/sh\nexit 1\n")
    os.chmod(os.path.join(fake_build, "patchcull"), 0o755)
    expect_one_line_error(run_sweep(fake_build, os.path.join(broken, "temporal.json", "sub")), "DATA_DIR",
                          "fig7_sweep.py with a DATA_DIR under a file")
    expect_one_line_error(run_sweep("--bogus"), "usage", "fig7_sweep.py with an option")
    expect_one_line_error(run(DATA, "--out", os.path.join(tmp, "no_such_dir")), "no_such_dir", "missing --out")
    expect_one_line_error(run(DATA, "--bogus"), "--bogus", "unknown option")

if failures:
    for f in failures:
        print("FAIL:", f)
    sys.exit(1)
print(f"plot_figures.py: {len(FIGURES)} figures drawn, 10 bad inputs refused")
