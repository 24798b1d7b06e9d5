#!/usr/bin/env python3
"""Writes inputs/boids.npy: 256 boids as a NumPy structured array matching
WGSL's `struct Boid { position: vec2<f32>, velocity: vec2<f32>, flock: u32,
_pad0: u32 }` (24 bytes). Two flocks of 128, each starting as a loose
cloud on its own side of the sky heading across it. Plain Python (no
NumPy): a fixed linear congruential generator, so the file is reproducible.
Run from examples/graphs: python3 inputs/make_boids.py"""
import math
import struct

COUNT = 256
state = 12345


def rand():
    """Uniform in [0, 1) from a 32-bit LCG (Numerical Recipes constants)."""
    global state
    state = (1664525 * state + 1013904223) & 0xFFFFFFFF
    return state / 2**32


body = bytearray()
for i in range(COUNT):
    flock = i % 2
    centre = (-0.45, 0.2) if flock == 0 else (0.45, -0.2)
    heading = (0.0 if flock == 0 else math.pi) + (rand() - 0.5) * 1.2
    radius = 0.35 * math.sqrt(rand())
    angle = 2 * math.pi * rand()
    speed = 0.25 + 0.15 * rand()
    px = centre[0] + radius * math.cos(angle)
    py = centre[1] + radius * math.sin(angle)
    vx = speed * math.cos(heading)
    vy = speed * math.sin(heading)
    body += struct.pack("<4f2I", px, py, vx, vy, flock, 0)

descr = "[('position', '<f4', (2,)), ('velocity', '<f4', (2,)), ('flock', '<u4'), ('_pad0', '<u4')]"
header = "{'descr': %s, 'fortran_order': False, 'shape': (%d,), }" % (descr, COUNT)
# Magic, version 1.0, header length, header padded with spaces to a
# multiple of 64 bytes and ended by a newline.
total = 10 + len(header) + 1
header += " " * (-total % 64) + "\n"
with open("inputs/boids.npy", "wb") as f:
    f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode("latin1") + bytes(body))
