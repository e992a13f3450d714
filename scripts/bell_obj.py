#!/usr/bin/env python3
"""Writes models/bell.obj: a church-bell shell as a surface of revolution (3-D spec §4.6).

Ten rings of twenty vertices from the lip (z = 0) up the waist to the shoulder, closed at the
crown by a fan around one vertex: 201 vertices, triangles only (so `hinge=` stiffens every
edge). The profile is a bell's: a flared lip, a narrowing waist, a rounded shoulder.
"""
import math
import pathlib

RINGS = [  # (height, radius), lip first
    (0.00, 1.00), (0.06, 0.93), (0.14, 0.82), (0.24, 0.72), (0.36, 0.65),
    (0.50, 0.61), (0.64, 0.59), (0.77, 0.57), (0.88, 0.51), (0.96, 0.38),
]
CROWN = 1.00
SEGMENTS = 20


def main():
    lines = ["# A bell shell for Ressort's objMesh: 10 rings of 20 vertices and a crown vertex.",
             "# Written by scripts/bell_obj.py; units are the bell's lip radius."]
    for z, r in RINGS:
        for k in range(SEGMENTS):
            a = 2 * math.pi * k / SEGMENTS
            lines.append(f"v {r * math.cos(a):.6f} {r * math.sin(a):.6f} {z:.6f}")
    lines.append(f"v 0.000000 0.000000 {CROWN:.6f}")
    top = len(RINGS) * SEGMENTS + 1
    idx = lambda ring, k: ring * SEGMENTS + (k % SEGMENTS) + 1
    for ring in range(len(RINGS) - 1):
        for k in range(SEGMENTS):
            a, b = idx(ring, k), idx(ring, k + 1)
            c, d = idx(ring + 1, k + 1), idx(ring + 1, k)
            # Counter-clockwise seen from outside (normals point away from the axis).
            lines.append(f"f {a} {b} {c}")
            lines.append(f"f {a} {c} {d}")
    last = len(RINGS) - 1
    for k in range(SEGMENTS):
        lines.append(f"f {idx(last, k)} {idx(last, k + 1)} {top}")
    out = pathlib.Path(__file__).resolve().parent.parent / "models" / "bell.obj"
    out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
