#!/usr/bin/env python3
"""Writes the grass example's inputs (SPEC 17 example c), from the math in
examples/render/README.md, with only Python's standard library:

  inputs/grass_blade.png    64 x 128 RGBA: four tapered blades in alpha
                            (tips towards v = 0) and an opaque soil patch
                            in the bottom-right 8 x 8 corner
  inputs/grass_blades.npy   float32 (N, 5): position xyz, uv per vertex;
                            three aligned layers of 100 cards, then the ground
  inputs/grass_indices.npy  uint16 (M,): two triangles per card

Run from the repository root: python3 examples/render/tools/make_grass.py
"""
import math
import os
import struct
import zlib

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "inputs")


def png(path, w, h, rgba):
    rows = b"".join(b"\x00" + bytes(rgba[y * w * 4:(y + 1) * w * 4]) for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))


def npy(path, descr, shape, data):
    header = "{'descr': '%s', 'fortran_order': False, 'shape': (%s), }" % (
        descr, ", ".join(str(s) for s in shape) + ("," if len(shape) == 1 else ""))
    pad = 64 - (10 + len(header) + 1) % 64
    header = header + " " * pad + "\n"
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + data)


def hash01(n):
    """A 32-bit integer hash (xorshift-multiply) mapped to [0, 1)."""
    n = (n * 0x9E3779B1) & 0xFFFFFFFF
    n ^= n >> 16
    n = (n * 0x85EBCA6B) & 0xFFFFFFFF
    n ^= n >> 13
    return n / 2**32


def blade_texture():
    w, h = 64, 128
    px = []
    # (base x, half width at the base, lean of the tip in texels, tip row)
    blades = [(14, 6.0, -5.0, 10), (28, 5.0, 4.0, 2), (42, 6.5, 7.0, 18), (54, 4.5, -3.0, 30)]
    for y in range(h):
        for x in range(w):
            soil = x >= w - 8 and y >= h - 8
            inside = False
            t_best = 0.0
            for bx, hw, lean, tip in blades:
                t = (h - 1 - y) / (h - 1 - tip)  # 0 at the root, 1 at the tip
                if 0.0 <= t <= 1.0 and abs(x + 0.5 - (bx + lean * t * t)) < hw * (1.0 - t):
                    inside = True
                    t_best = max(t_best, t)
            if soil:
                px += [92, 70, 44, 255]
            else:
                # Transparent texels carry the blade colour too, so linear
                # filtering at an edge does not darken it.
                g = t_best if inside else 0.5
                px += [int(255 * (0.18 + 0.25 * g)), int(255 * (0.42 + 0.38 * g)), int(255 * 0.12), 255 if inside else 0]
    return w, h, px


def cards():
    verts = []
    idx = []
    for layer, z in enumerate([0.0, 0.5, 1.0]):
        for i in range(100):
            n = layer * 1000 + i
            x = -2.5 + 0.05 * i + 0.04 * (hash01(n) - 0.5)
            width = 0.28 + 0.06 * hash01(n + 7)
            height = 0.35 + 0.15 * hash01(n + 13)
            # Cards of one layer lie in the plane z (aligned, facing the camera).
            base = len(verts) // 5
            for (dx, y, u, v) in [(-0.5, 0.0, 0.0, 1.0), (0.5, 0.0, 1.0, 1.0), (0.5, height, 1.0, 0.0), (-0.5, height, 0.0, 0.0)]:
                verts += [x + dx * width, y, z, u, v]
            idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    # The ground: one quad at y = 0 reading the soil patch (v > 0.5: never swayed).
    base = len(verts) // 5
    for (x, z) in [(-4.0, -1.5), (4.0, -1.5), (4.0, 4.0), (-4.0, 4.0)]:
        verts += [x, 0.0, z, 0.97, 0.97]
    idx += [base, base + 2, base + 1, base, base + 3, base + 2]
    return verts, idx


def main():
    w, h, px = blade_texture()
    png(os.path.join(HERE, "grass_blade.png"), w, h, px)
    verts, idx = cards()
    npy(os.path.join(HERE, "grass_blades.npy"), "<f4", (len(verts) // 5, 5), struct.pack("<%df" % len(verts), *verts))
    npy(os.path.join(HERE, "grass_indices.npy"), "<u2", (len(idx),), struct.pack("<%dH" % len(idx), *idx))
    print("%d vertices, %d indices" % (len(verts) // 5, len(idx)))


if __name__ == "__main__":
    main()
