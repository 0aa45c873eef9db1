#!/usr/bin/env python3
"""A placed twin's packing height against the experiment's, frame by frame: each frame's mean
grain height z / d, the twin's runs at the two frictions nearest TRUE minus the experiment's
(1e-3 d; with the runs' spread), then the friction each frame's mean height implies (a
quadratic in ln mu_s through the runs within a factor 2.8 of TRUE) (docs/CALIBRATION.md,
"The placed packing tapped by its own settle").
Usage: scripts/placed_height_gap.py RUNS_DIR FIRST:LAST TRUE_MU_S EXPERIMENT.h5
       (FIRST: the placed frame's cycle, e.g. 20 for a window 21:30)"""
import glob
import re
import sys

import h5py
import numpy as np


def mean_heights(path, cycles):
    with h5py.File(path, "r") as f:
        g = f["particles/grains"]
        unit = g["position/value"].attrs.get("unit", b"m")
        scale = {"m": 1.0, "mm": 1e-3}[unit.decode() if isinstance(unit, bytes) else unit]
        pos, step = g["position/value"][...] * scale, list(g["position/step"][...])
        d = 2 * np.nanmedian(g["radius"][...]) * scale
    return np.array([np.nanmean(pos[step.index(c)][:, 2]) / d * 1000 for c in cycles])


runs, window, truth, experiment = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
first, last = map(int, window.split(":"))
cycles = list(range(first, last + 1))
measured = mean_heights(experiment, cycles)
by_friction = {}
for path in glob.glob(runs + "/mu_s_*_seed_*.h5"):
    mu = float(re.search(r"mu_s_([0-9.]+)_seed_", path).group(1))
    by_friction.setdefault(mu, []).append(mean_heights(path, cycles))
frictions = np.array(sorted(by_friction))
print("cycles", cycles)
for mu in sorted(frictions, key=lambda m: abs(np.log(m / truth)))[:2]:
    v = np.array(by_friction[mu])
    print(f"twin {mu} ({len(v)}) minus experiment:", np.round(v.mean(0) - measured, 1),
          "spread", np.round(v.std(0).mean(), 1))
mean = np.array([np.mean(by_friction[m], 0) for m in frictions])
near = np.abs(np.log(frictions / truth)) < np.log(2.8)
implied = []
for k in range(len(cycles)):
    c = np.polyfit(np.log(frictions[near]), mean[near, k], 2)
    roots = [r.real for r in np.roots(c - [0, 0, measured[k]]) if abs(r.imag) < 1e-9]
    implied.append(np.exp(min(roots, key=lambda r: abs(r - np.log(truth)))) if roots else np.nan)
print("friction implied by the mean height:", np.round(implied, 3))
