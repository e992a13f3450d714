#!/usr/bin/env python3
"""Writes the bell shells of models/ for Ressort's objMesh (3-D spec §4.6): surfaces of
revolution from the lip (z = 0) up the waist to the shoulder, closed at the crown by a fan
around one vertex, triangles only (so `hinge=` stiffens every edge). The profile is a bell's:
a flared lip, a narrowing waist, a rounded shoulder.

* models/bell.obj: ten rings of twenty vertices and the crown, 201 vertices (the 3-D
  benchmark's bell, `engine/benches/space_models.rs`);
* models/bell-coarse.obj: five rings of twelve (every other ring of the profile, and its
  shoulder) and the crown, 61 vertices: Mesh Bell's, light enough for eight voices in real
  time.
"""
import math
import pathlib

RINGS = [  # (height, radius), lip first
    (0.00, 1.00), (0.06, 0.93), (0.14, 0.82), (0.24, 0.72), (0.36, 0.65),
    (0.50, 0.61), (0.64, 0.59), (0.77, 0.57), (0.88, 0.51), (0.96, 0.38),
]
CROWN = 1.00


def bell(rings, segments, name, what):
    lines = [f"# A bell shell for Ressort's objMesh: {what}.",
             "# Written by scripts/bell_obj.py; units are the bell's lip radius."]
    for z, r in rings:
        for k in range(segments):
            a = 2 * math.pi * k / segments
            lines.append(f"v {r * math.cos(a):.6f} {r * math.sin(a):.6f} {z:.6f}")
    lines.append(f"v 0.000000 0.000000 {CROWN:.6f}")
    top = len(rings) * segments + 1
    idx = lambda ring, k: ring * segments + (k % segments) + 1
    for ring in range(len(rings) - 1):
        for k in range(segments):
            a, b = idx(ring, k), idx(ring, k + 1)
            c, d = idx(ring + 1, k + 1), idx(ring + 1, k)
            # Counter-clockwise seen from outside (normals point away from the axis).
            lines.append(f"f {a} {b} {c}")
            lines.append(f"f {a} {c} {d}")
    last = len(rings) - 1
    for k in range(segments):
        lines.append(f"f {idx(last, k)} {idx(last, k + 1)} {top}")
    out = pathlib.Path(__file__).resolve().parent.parent / "models" / name
    out.write_text("\n".join(lines) + "\n")


def main():
    bell(RINGS, 20, "bell.obj", "10 rings of 20 vertices and a crown vertex")
    coarse = [RINGS[i] for i in (0, 2, 4, 6, 9)]
    bell(coarse, 12, "bell-coarse.obj", "5 rings of 12 vertices and a crown vertex")


if __name__ == "__main__":
    main()
