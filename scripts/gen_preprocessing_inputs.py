#!/usr/bin/env python3
"""Inputs of docs/PERFORMANCE.md's preprocessing figures.

  gen_preprocessing_inputs.py ngon N [closed]   one N-gon (closed: a second one, reversed, on the same corners)
  gen_preprocessing_inputs.py fan N [closed]    vertex 1 of valence N: N triangles (closed: a second fan below)
  gen_preprocessing_inputs.py qfan N [closed]   vertex 1 of valence N: N quads (closed: a second fan below)
  gen_preprocessing_inputs.py span MODEL.obj    MODEL with every face's texcoords spanning [0,1]^2
  gen_preprocessing_inputs.py map SIZE OUT.png  a SIZE x SIZE 8-bit grey PNG of random heights

OBJ goes to stdout.
"""
import math
import random
import struct
import sys
import zlib


def ring(n, r=1.0, phase=0.0):
    return [f"v {r * math.cos(2 * math.pi * (k + phase) / n):.6f} {r * math.sin(2 * math.pi * (k + phase) / n):.6f} 0"
            for k in range(n)]


def ngon(n, closed):
    out = ring(n) + ["f " + " ".join(str(k + 1) for k in range(n))]
    if closed:
        out.append("f " + " ".join(str(k + 1) for k in reversed(range(n))))
    return out


def fan(n, closed, quads):
    out = ["v 0 0 0.3"] + ring(n) + (ring(n, 1.2, 0.5) if quads else []) + (["v 0 0 -0.3"] if closed else [])
    R = lambda k: 2 + k % n
    M = lambda k: 2 + n + k % n
    B = 2 + (2 * n if quads else n)
    for k in range(n):
        if quads:
            out.append(f"f 1 {R(k)} {M(k)} {R(k + 1)}")
            if closed:
                out.append(f"f {B} {R(k + 1)} {M(k)} {R(k)}")
        else:
            out.append(f"f 1 {R(k)} {R(k + 1)}")
            if closed:
                out.append(f"f {B} {R(k + 1)} {R(k)}")
    return out


def span(path):
    out = ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1"]
    for line in open(path):
        if line.startswith("vt"):
            continue
        if line.startswith("f "):
            vs = [p.split("/")[0] for p in line.split()[1:]]
            out.append("f " + " ".join(f"{v}/{1 + i % 4}" for i, v in enumerate(vs)))
        else:
            out.append(line.rstrip("\n"))
    return out


def png(size, path):
    random.seed(1)
    rows = [bytes([0]) + bytes(random.getrandbits(8) for _ in range(size)) for _ in range(64)]
    raw = b"".join(rows[y % 64] for y in range(size))
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 0, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def main(argv):
    kind = argv[1] if len(argv) > 1 else ""
    if kind in ("ngon", "fan", "qfan") and len(argv) >= 3:
        n, closed = int(argv[2]), len(argv) > 3 and argv[3] == "closed"
        lines = ngon(n, closed) if kind == "ngon" else fan(n, closed, kind == "qfan")
    elif kind == "span" and len(argv) == 3:
        lines = span(argv[2])
    elif kind == "map" and len(argv) == 4:
        png(int(argv[2]), argv[3])
        return 0
    else:
        sys.stderr.write(__doc__)
        return 2
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
