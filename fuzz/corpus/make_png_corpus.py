#!/usr/bin/env python3
"""Writes fuzz/corpus/png/: small PNGs of every kind the height-map loader meets (8/16-bit grey,
grey+alpha, RGB, RGBA, palette, interlaced, 1x1, extra chunks) plus truncated and damaged ones.
Deterministic; run it from anywhere to regenerate the checked-in files."""
import os
import struct
import zlib

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "png")


def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def png(width, height, depth, colour, rows, extra=b"", interlace=0, palette=None, raw=None):
    """rows: unfiltered scanlines (filter type 0 is prepended), or raw: the filtered bytes."""
    ihdr = struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, interlace)
    if raw is None:
        raw = b"".join(b"\0" + r for r in rows)
    body = chunk(b"IHDR", ihdr)
    if palette is not None:
        body += chunk(b"PLTE", palette)
    body += extra + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    return b"\x89PNG\r\n\x1a\n" + body


def samples(values, depth):
    if depth == 16:
        return b"".join(struct.pack(">H", v) for v in values)
    if depth == 8:
        return bytes(values)
    per_byte = 8 // depth  # 1, 2, 4 bits: packed, high bits first
    out = bytearray()
    for i in range(0, len(values), per_byte):
        b = 0
        for k, v in enumerate(values[i:i + per_byte]):
            b |= v << (8 - depth * (k + 1))
        out.append(b)
    return bytes(out)


def grid(width, height, channels, maxv, seed):
    rows = []
    for y in range(height):
        rows.append([(x * 37 + y * 91 + c * 53 + seed) % (maxv + 1) for x in range(width) for c in range(channels)])
    return rows


def make(width, height, depth, colour, channels, seed=0, **kw):
    maxv = (1 << depth) - 1
    return png(width, height, depth, colour, [samples(r, depth) for r in grid(width, height, channels, maxv, seed)], **kw)


def main():
    os.makedirs(OUT, exist_ok=True)
    files = {
        "grey8_4x3.png": make(4, 3, 8, 0, 1),
        "grey16_4x3.png": make(4, 3, 16, 0, 1, seed=1000),
        "grey1_9x2.png": make(9, 2, 1, 0, 1),
        "grey4_5x5.png": make(5, 5, 4, 0, 1),
        "grey_alpha8_3x3.png": make(3, 3, 8, 4, 2),
        "grey_alpha16_2x2.png": make(2, 2, 16, 4, 2),
        "rgb8_4x4.png": make(4, 4, 8, 2, 3),
        "rgb16_3x2.png": make(3, 2, 16, 2, 3, seed=7),
        "rgba8_2x5.png": make(2, 5, 8, 6, 4),
        "rgba16_2x2.png": make(2, 2, 16, 6, 4),
        "palette8_4x4.png": make(4, 4, 8, 3, 1, palette=bytes(range(48)), seed=3),
        "palette2_6x3.png": make(6, 3, 2, 3, 1, palette=bytes([0, 0, 0, 255, 255, 255, 10, 20, 30, 90, 80, 70])),
        "grey8_1x1.png": make(1, 1, 8, 0, 1),
        "text_chunk_grey8_4x4.png": make(4, 4, 8, 0, 1, extra=chunk(b"tEXt", b"Comment\0height map")),
    }
    # Adam7 interlacing: seven sub-images, each row filtered separately.
    passes = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]
    w = h = 9
    raw = b""
    for x0, y0, dx, dy in passes:
        xs, ys = range(x0, w, dx), range(y0, h, dy)
        if not xs or not ys:
            continue
        for y in ys:
            raw += b"\0" + bytes((x * 29 + y * 13) % 256 for x in xs)
    files["interlaced_grey8_9x9.png"] = png(w, h, 8, 0, None, interlace=1, raw=raw)
    good = files["grey8_4x3.png"]
    files["truncated_in_idat.png"] = good[: len(good) - 20]
    files["truncated_in_ihdr.png"] = good[:20]
    files["signature_only.png"] = good[:8]
    files["huge_dimensions.png"] = png(1 << 24, 1 << 24, 8, 0, [b"\0" * 4])
    files["zero_width.png"] = png(0, 3, 8, 0, [b"", b"", b""])
    files["bad_depth.png"] = png(4, 1, 7, 0, [b"\0\0\0\0"])
    files["bad_colour_type.png"] = png(4, 1, 8, 5, [b"\0\0\0\0"])
    files["no_idat.png"] = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 0, 0, 0, 0)) + chunk(b"IEND", b"")
    files["bad_filter.png"] = png(2, 2, 8, 0, None, raw=b"\x09\x01\x02\x07\x03\x04")  # filter types 9 and 7
    files["not_png.jpg"] = b"\xff\xd8\xff\xe0\0\x10JFIF\0\x01\x01\0\0\x01\0\x01\0\0\xff\xd9"
    for name, data in files.items():
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
