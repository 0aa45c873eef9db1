"""Whether a model of a scan's centre errors (a normal error and a pull towards the near
neighbours, scripts/placed_frame_noise.py) gives the scans' near-contact distances: their
10, 25 and 50 % quantiles over 0.97-1.02 d in three bins of |u_z| (the contact's direction
against z), in the scans and in a simulated run (exact) moved by each model given, in d
(docs/CALIBRATION.md, "What the scans' centres share").
Usage: /usr/bin/python3 scripts/contact_distances_under_error_model.py TRACKS.h5 RUN.h5 FIRST:LAST \
           NOISE_XY,NOISE_Z,PULL_XY,PULL_Z [...]      (um; the run's diameter, cycles FIRST-LAST)"""
import os
import sys

import h5py
import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from placed_frame_noise import SCALE, as_scanned  # noqa: E402

EDGES = (0, 0.45, 0.8, 1.0)
LO, HI = 0.97, 1.02


def frames(path, cycles):
    with h5py.File(path, "r") as f:
        p = f["/particles/grains/position/value"]
        unit = p.attrs.get("unit", b"m")
        unit = unit.decode() if isinstance(unit, bytes) else unit
        steps = list(f["/particles/grains/position/step"][...])
        xs = [p[steps.index(c)] / SCALE[unit] for c in cycles]
    return [x[np.isfinite(x).all(1)] for x in xs]


def quantiles(xs, diameter):
    d, uz = [], []
    for x in xs:
        pairs = cKDTree(x).query_pairs(HI * diameter, output_type="ndarray")
        v = x[pairs[:, 1]] - x[pairs[:, 0]]
        r = np.linalg.norm(v, axis=1)
        near = r > LO * diameter
        d.append(r[near] / diameter)
        uz.append(np.abs(v[near, 2]) / r[near])
    d, uz = np.concatenate(d), np.concatenate(uz)
    return np.concatenate([np.quantile(d[(uz >= a) & (uz < b)], [0.1, 0.25, 0.5])
                           for a, b in zip(EDGES[:-1], EDGES[1:])])


scans, run = sys.argv[1], sys.argv[2]
first, last = map(int, sys.argv[3].split(":"))
cycles = range(first, last + 1)
with h5py.File(run, "r") as f:
    diameter = 2 * np.nanmedian(f["/particles/grains/radius"][...])
exact = frames(run, cycles)
target = quantiles(frames(scans, cycles), diameter)
print("|u_z| bins", EDGES, "; quantiles 10, 25, 50 % of each, in d")
print("scans          ", np.round(target, 5))
print("run, exact     ", np.round(quantiles(exact, diameter) - target, 5), "(minus the scans')")
for model in sys.argv[4:]:
    sxy, sz, pxy, pz = (float(v) * 1e-6 for v in model.split(","))
    rng = np.random.default_rng(7)
    moved = [as_scanned(x, diameter, np.array([sxy, sxy, sz]), np.array([pxy, pxy, pz]), rng)
             for x in exact]
    print(f"run, {model:10s}", np.round(quantiles(moved, diameter) - target, 5), "(minus the scans')")
