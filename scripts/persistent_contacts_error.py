#!/usr/bin/env python3
"""The scans' displacement error read from their persistent contacts: for each pair of
grains touching (centres within 1.01 d) at the ends of a cycle c-1 -> c, the change of the
distance between their centres, whose true part is small (the DEM's: a robust spread of
~1 um); its robust spread (1.4826 x the median absolute deviation), by the contact's
direction: horizontal (|n_z| < 0.3) and vertical (|n_z| > 0.8). Independent errors of s per
frame and grain would spread it by 2 s along the contact, so half of it is the per-frame
error that moves the end-of-cycle displacements as the scans' own errors do (consecutive
frames' errors being partly shared): give that to scripts/scan_displacement_noise.py
(docs/CALIBRATION.md, "The end-of-cycle displacement on a placed twin").
Usage: scripts/persistent_contacts_error.py RUN.h5 FIRST:LAST   (scans or a DEM run)"""
import sys

import h5py
import numpy as np
from scipy.spatial import cKDTree

with h5py.File(sys.argv[1], "r") as f:
    g = f["particles/grains"]
    unit = g["position/value"].attrs.get("unit", b"m")
    scale = {"m": 1.0, "mm": 1e-3}[unit.decode() if isinstance(unit, bytes) else unit]
    pos, step = g["position/value"][...] * scale, list(g["position/step"][...])
    d = 2 * np.nanmedian(g["radius"][...]) * scale if "radius" in g else 0.005
first, last = map(int, sys.argv[2].split(":"))
horizontal, vertical = [], []
for c in range(first, last + 1):
    a, b = pos[step.index(c - 1)], pos[step.index(c)]
    seen = np.where(np.all(np.isfinite(a), 1) & np.all(np.isfinite(b), 1))[0]
    pairs = np.array(sorted(cKDTree(a[seen]).query_pairs(1.01 * d)))
    i, j = seen[pairs[:, 0]], seen[pairs[:, 1]]
    before, after = np.linalg.norm(a[j] - a[i], axis=1), np.linalg.norm(b[j] - b[i], axis=1)
    kept = after < 1.01 * d
    n_z = np.abs((a[j] - a[i])[kept, 2] / before[kept])
    change = (after - before)[kept] * 1e6
    horizontal += list(change[n_z < 0.3])
    vertical += list(change[n_z > 0.8])


def spread(x):
    x = np.asarray(x)
    return 1.4826 * np.median(np.abs(x - np.median(x)))


h, v = spread(horizontal), spread(vertical)
print(f"persistent contacts' change (um, robust spread): horizontal {h:.2f} ({len(horizontal)}), "
      f"vertical {v:.2f} ({len(vertical)}); the per-frame error that moves the displacements: "
      f"{h / 2:.2f} across, {v / 2:.2f} along z")
