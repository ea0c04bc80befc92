#!/usr/bin/env python3
"""Writes scenes/assets/terrain.png, the terrain of scenes/river_terrain.json.

Usage:
    python3 scripts/make_heightfield.py [--out PATH] [--width 128] [--depth 64]

Pure Python 3 (zlib and struct only, no numpy or PIL) and deterministic: the same arguments give the same
bytes. The image is a 16-bit greyscale PNG, `width` pixels along x and `depth` along z. As a heightfield
collider (docs/scene-format.md) pixel (0, 0) lies at (-x, -z), black is height 0 and white is the collider's
`height`, so the terrain:

  - slopes down along +x, from about 0.8 of white at the left edge to a nearly flat basin (0.04 of white)
    over the last fifth;
  - has a winding channel along x through the middle of z, 0.22 of white deep, that fades out in the basin;
  - has raised banks at both z edges and a few smooth bumps and a low cross ridge beside and in the channel,
    for the water to split around and spill over.

Every height is a smooth function (no noise; where the channel would cut below black it is eased onto a floor
just above it), sampled so that the first and last pixels' centres lie on the terrain's edges (as the collider
reads them) and stored as round(65535 * h).
"""

import argparse
import math
import os
import struct
import zlib


def smoothstep(a, b, t):
    t = min(max((t - a) / (b - a), 0.0), 1.0)
    return t * t * (3.0 - 2.0 * t)


def channel_centre(u):
    """z (0..1) of the channel's centre line at x = u (0..1)."""
    return 0.5 + 0.14 * math.sin(2.0 * math.pi * (1.1 * u + 0.1))


def terrain(u, v):
    """Height in 0..1 of white at (u, v), both 0..1 (u along x, v along z)."""
    # The slope: falls from 0.8 at u = 0 and eases into a flat basin at u >= 0.8.
    s = smoothstep(0.0, 0.8, u)
    h = 0.04 + 0.76 * (1.0 - s) * (1.0 - 0.25 * s)
    # The channel, Gaussian across, fading out in the basin.
    fade = 1.0 - smoothstep(0.7, 0.85, u)
    dz = (v - channel_centre(u)) / 0.11
    h -= 0.22 * fade * math.exp(-dz * dz)
    # Raised banks at both z edges (they keep the water off the tank's side walls).
    h += 0.15 * (1.0 - smoothstep(0.0, 0.16, v)) * fade
    h += 0.15 * smoothstep(0.84, 1.0, v) * fade
    # Bumps: (u, v, height, radius u, radius v).
    for bu, bv, bh, ru, rv in (
        (0.28, 0.24, 0.14, 0.05, 0.10),
        (0.46, 0.76, 0.12, 0.06, 0.10),
        (0.62, 0.28, 0.10, 0.05, 0.12),
        (0.18, 0.74, 0.10, 0.04, 0.08),
    ):
        du, dv = (u - bu) / ru, (v - bv) / rv
        h += bh * math.exp(-(du * du + dv * dv))
    # A low ridge across the channel, which the water has to pool behind and spill over.
    du = (u - 0.40) / 0.025
    h += 0.08 * math.exp(-du * du)
    # A smooth floor at 0 where the channel cuts below it (a kink would make a sharp edge for the water).
    h = 0.5 * (h + math.sqrt(h * h + 0.03 * 0.03))
    return min(max(h, 0.0), 1.0)


def png_chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def write_png16(path, width, height, rows):
    """rows: `height` lists of `width` integers 0..65535, the first row at the top of the image."""
    raw = bytearray()
    for row in rows:
        raw.append(0)  # filter: none
        raw += struct.pack(">%dH" % width, *row)
    data = b"\x89PNG\r\n\x1a\n"
    data += png_chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 16, 0, 0, 0, 0))  # 16-bit grey
    data += png_chunk(b"IDAT", zlib.compress(bytes(raw), 9))
    data += png_chunk(b"IEND", b"")
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data)
    return len(data)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=os.path.join(here, "..", "scenes", "assets", "terrain.png"))
    parser.add_argument("--width", type=int, default=128, help="pixels along x")
    parser.add_argument("--depth", type=int, default=64, help="pixels along z")
    args = parser.parse_args()
    if args.width < 2 or args.depth < 2:
        parser.error("the image needs at least 2 x 2 pixels")
    rows = []
    for j in range(args.depth):
        v = j / (args.depth - 1)
        rows.append([int(round(65535 * terrain(i / (args.width - 1), v))) for i in range(args.width)])
    size = write_png16(args.out, args.width, args.depth, rows)
    print("wrote %s (%d x %d, 16-bit grey, %d bytes)" % (os.path.normpath(args.out), args.width, args.depth, size))


if __name__ == "__main__":
    main()
