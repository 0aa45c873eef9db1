#!/usr/bin/env python3
"""Writes sample_data/tracked_grains.csv: a SYNTHETIC set of tracked grains.

It stands in for what a tracker (trackpy, a lab's MATLAB code) gives for laser-sheet scans
of a packing taken at the end of successive compression cycles. Nothing here is measured:
grains sit on a jittered lattice, and from cycle to cycle each gets a random irreversible
displacement and a random rotation of its cavity axis whose sizes decay with the cycle
number as a power law (exponents 0.7 and 0.6, as the paper reports) towards a steady value,
plus a common drift of the whole packing. A tracker's imperfections are added: position
noise, grains missed in a scan, axes not seen, grains touching through their hole.

Coordinates are voxel indices of a 12-voxel grain diameter (0.5 cm grains), with slices
1.5 times coarser than the pixels: voxel size 0.41667 x 0.41667 x 0.625 mm.
Deterministic: re-running gives the same file. Plain Python, no packages needed.
"""
import math
import os
import random

rng = random.Random(20201121)
VOXEL = (5.0 / 12, 5.0 / 12, 0.625)  # mm
DIAMETER_MM = 5.0
NX, NY, NZ = 10, 10, 8
CYCLES = 15
BOX_MM = (NX * DIAMETER_MM + 2.0, NY * DIAMETER_MM + 2.0, NZ * DIAMETER_MM + 2.0)


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def random_unit():
    return unit([rng.gauss(0, 1) for _ in range(3)])


def rotate(a, axis, angle):
    """Rodrigues rotation of vector a about unit axis by angle."""
    c, s = math.cos(angle), math.sin(angle)
    d = sum(x * y for x, y in zip(axis, a))
    cross = [axis[1] * a[2] - axis[2] * a[1], axis[2] * a[0] - axis[0] * a[2],
             axis[0] * a[1] - axis[1] * a[0]]
    return [a[i] * c + cross[i] * s + axis[i] * d * (1 - c) for i in range(3)]


grains = []
for i in range(NX):
    for j in range(NY):
        for k in range(NZ):
            x = [1.0 + DIAMETER_MM * (i + 0.5 + (0.5 if k % 2 else 0) * 0.5),
                 1.0 + DIAMETER_MM * (j + 0.5 + (0.5 if k % 2 else 0) * 0.5),
                 1.0 + DIAMETER_MM * (k + 0.5) * 0.9]
            x = [c + rng.gauss(0, 0.15) for c in x]
            grains.append({"x": x, "a": random_unit(), "r": DIAMETER_MM / 2 * (1 + rng.gauss(0, 0.01))})

rows = []
for cycle in range(CYCLES + 1):
    if cycle > 0:
        step_mm = 0.02 + 0.25 * cycle ** -0.7   # mean irreversible displacement per cycle
        step_rad = 0.01 + 0.12 * cycle ** -0.6  # mean rotation of the axis per cycle
        drift = [0.05 * rng.gauss(0, 1), 0.08, 0.0]  # the packing creeps along y
        for g in grains:
            # Grains near the driven wall (y = 0) move more: a crude shear zone.
            zone = 1.0 + 1.5 * math.exp(-g["x"][1] / 15.0)
            g["x"] = [g["x"][d] + drift[d] + zone * step_mm * rng.gauss(0, 1) / math.sqrt(3)
                      for d in range(3)]
            angle = abs(rng.gauss(0, 1)) * step_rad * zone
            turn_axis = random_unit()
            g["a"] = unit(rotate(g["a"], turn_axis, angle))
    for pid, g in enumerate(grains):
        if rng.random() < 0.004:
            continue  # missed in this scan
        vox = [g["x"][d] / VOXEL[d] + rng.gauss(0, 0.03) for d in range(3)]
        sign = 1 if rng.random() < 0.5 else -1  # an axis is a line: its sign is arbitrary
        a = [sign * g["a"][d] / VOXEL[d] for d in range(3)]  # direction in voxel space
        seen = rng.random() > 0.01
        hole = 1 if rng.random() < 0.05 else 0
        rows.append((cycle, pid, vox, a if seen else None, g["r"] / VOXEL[0], hole))

here = os.path.dirname(os.path.abspath(__file__))
out = os.path.join(here, "..", "sample_data", "tracked_grains.csv")
with open(out, "w") as f:
    f.write("frame,particle,x,y,z,ax,ay,az,radius,hole_contact\n")
    for cycle, pid, vox, a, r, hole in rows:
        axis = ",".join(f"{c:.6f}" for c in a) if a else ",,"
        f.write(f"{cycle},{pid},{vox[0]:.4f},{vox[1]:.4f},{vox[2]:.4f},{axis},{r:.3f},{hole}\n")
print(f"wrote {out}: {len(rows)} rows, {len(grains)} grains, {CYCLES + 1} scans")
print("box in voxels: 0,0,0,%.2f,%.2f,%.2f" % tuple(BOX_MM[d] / VOXEL[d] for d in range(3)))
