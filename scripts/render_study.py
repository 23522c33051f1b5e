"""What scripts/sathe_study.py and scripts/backpatch_tess_study.py share: the one-line error,
one `patchcull render --json` run with its frames parsed, and the options both take (--cli,
--size, --frames, --rounds, --json; each script adds its own list options through `extra`).
"""
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(prog, message):
    # Printable and bounded, whatever an argument holds.
    text = message.encode("ascii", "backslashreplace").decode("ascii").replace("\n", "\\n")
    print(f"{prog}: error: {text[:500]}", file=sys.stderr)
    sys.exit(2)


def render_json(prog, cli, path, level, size, frames, mode_args):
    """`render PATH --tess L --size WxH --frames N --json MODE_ARGS`: (the JSON object, frames 1..N-1,
    the timed ones: frame 0 compiles the shaders). A CLI that fails is a one-line error naming it."""
    cmd = [cli, "render", path, "--tess", str(level), "--size", size, "--frames", str(frames), "--json", *mode_args]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as e:  # e.g. the binary being relinked by a build
        fail(prog, f"--cli: {cli}: {e.strerror}")
    if r.returncode != 0:
        last = (r.stderr.strip().splitlines() or ["(no output)"])[-1]
        fail(prog, f"{' '.join(cmd[1:])}: exit status {r.returncode}: {last}")
    out = json.loads(r.stdout)
    return out, out["frames"][1:]


def parse_options(prog, doc, argv, defaults, extra):
    """Options of a study: DEFAULTS (a dict holding at least cli, size, frames, rounds, json) updated
    from ARGV; EXTRA maps a script's own flags to a function(value) -> (key, parsed value) that
    fails itself on a bad value. -h/--help prints DOC and exits 0."""
    opts = dict(defaults)
    flags = ("--cli", "--size", "--frames", "--rounds", "--json", *extra)
    i = 0
    while i < len(argv):
        flag = argv[i]
        if flag in ("-h", "--help"):
            print(doc)
            sys.exit(0)
        if flag not in flags:
            fail(prog, f"unknown option {flag!r} (see --help)")
        if i + 1 >= len(argv) or not argv[i + 1]:
            fail(prog, f"{flag}: expected a value")
        value = argv[i + 1]
        i += 2
        if flag == "--cli":
            if not os.access(value, os.X_OK):
                fail(prog, f"--cli: {value}: not an executable file")
            opts["cli"] = value
        elif flag == "--size":
            w, _, h = value.partition("x")
            if not (w.isdigit() and h.isdigit() and 16 <= int(w) <= 4096 and 16 <= int(h) <= 4096):
                fail(prog, f"--size: expected WxH with 16..4096 each, got {value!r}")
            opts["size"] = value
        elif flag in ("--frames", "--rounds"):
            lo, hi = (2, 100) if flag == "--frames" else (1, 20)
            if not (value.isdigit() and lo <= int(value) <= hi):
                fail(prog, f"{flag}: expected an integer in {lo}..{hi}, got {value!r}")
            opts[flag[2:]] = int(value)
        elif flag == "--json":
            opts["json"] = value
        else:
            key, parsed = extra[flag](value)
            opts[key] = parsed
    if not os.access(opts["cli"], os.X_OK):
        fail(prog, f"--cli: {opts['cli']}: not an executable file (build patchcull_cli first)")
    return opts
