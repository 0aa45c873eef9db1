#!/usr/bin/env python3
"""How far the scans' locating errors move the mean end-of-cycle displacement |dr| / d, the
window mean (drift removed, grains more than 1 d inside): the tracked scans', the DEM
truth's they were drawn from, and the truth's with every frame's positions moved by an
independent normal error of the given size (as calibrate's noise check moves them); the
scans' errors in consecutive frames being partly shared, the last overstates the first
(docs/CALIBRATION.md, "The end-of-cycle displacement on a placed twin").
Usage: scripts/scan_displacement_noise.py TRACKS.h5 DEM.h5 FIRST:LAST ACROSS_UM ALONG_Z_UM"""
import sys

import h5py
import numpy as np


def frames(path):
    with h5py.File(path, "r") as f:
        g = f["particles/grains"]
        unit = g["position/value"].attrs.get("unit", b"m")
        scale = {"m": 1.0, "mm": 1e-3}[unit.decode() if isinstance(unit, bytes) else unit]
        return g["position/value"][...] * scale, list(g["position/step"][...])


def mean_dr(pos, step, first, last, d, error=None, seed=1):
    moved = pos if error is None else pos + np.random.default_rng(seed).normal(
        size=pos.shape) * np.asarray(error)
    out = []
    for c in range(first, last + 1):
        a0 = pos[step.index(c - 1)]  # the grains chosen by their true place
        a, b = moved[step.index(c - 1)], moved[step.index(c)]
        lo, hi = np.nanmin(a0, 0) + d, np.nanmax(a0, 0) - d
        ok = np.all((a0 > lo) & (a0 < hi), 1) & np.all(np.isfinite(a), 1) & np.all(
            np.isfinite(b), 1)
        u = (b[ok] - a[ok]) / d
        out.append(np.linalg.norm(u - u.mean(0), axis=1).mean())
    return np.mean(out)


tracks, truth = frames(sys.argv[1]), frames(sys.argv[2])
first, last = map(int, sys.argv[3].split(":"))
across, along_z = float(sys.argv[4]) * 1e-6, float(sys.argv[5]) * 1e-6
with h5py.File(sys.argv[2], "r") as f:
    d = 2 * np.nanmedian(f["particles/grains/radius"][...])
exact = mean_dr(*truth, first, last, d)
scans = mean_dr(*tracks, first, last, d)
model = mean_dr(*truth, first, last, d, (across, across, along_z))
print(f"truth {exact:.5f}  scans {scans:.5f} ({scans - exact:+.5f})  "
      f"truth moved by {across * 1e6:g}/{along_z * 1e6:g} um {model:.5f} ({model - exact:+.5f}); "
      f"the scans' share of the model's move {(scans - exact) / (model - exact):.2f}")
