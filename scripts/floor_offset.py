#!/usr/bin/env python3
"""How far a store's packing sits above its container floor (docs/CALIBRATION.md, "What the
scans' frame carries: their floor 73 um low"): per frame, its bottom layer's median gap to the
floor (the grains whose bottom, at the nominal radius, lies within half a diameter of the
lowest; a DEM packing's press into the floor, a few um below 0), the 10th percentile of its
lowest 300 grains' gaps, and, given the truth it was drawn from, the mean z of all its grains
less the truth's (and across, x and y). With --lower OUT.h5: a copy of the store with every
position lowered by that mean offset (the truth's, needed then).
Usage: scripts/floor_offset.py STORE.h5 --radius 2.5e-3 [--truth TRUTH.h5 [--lower OUT.h5]]"""
import argparse
import shutil

import h5py
import numpy as np


def positions(path):
    g = h5py.File(path, "r")["particles/grains/position"]
    unit = g["value"].attrs.get("unit", b"m")
    scale = {"m": 1.0, "mm": 1e-3}[unit.decode() if isinstance(unit, bytes) else unit]
    return list(g["step"][...]), g["value"][...] * scale, scale


parser = argparse.ArgumentParser()
parser.add_argument("store")
parser.add_argument("--radius", type=float, required=True, help="nominal grain radius, m")
parser.add_argument("--truth")
parser.add_argument("--lower")
a = parser.parse_args()
steps, x, scale = positions(a.store)
truth = positions(a.truth) if a.truth else None
offsets = []
print("cycle,bottom_layer_median_gap_um,lowest300_p10_gap_um,grains_in_bottom_layer" +
      (",mean_offset_x_um,mean_offset_y_um,mean_offset_z_um" if truth else ""))
for k, cycle in enumerate(steps):
    frame = x[k][np.isfinite(x[k][:, 2])]
    gap = np.sort(frame[:, 2] - a.radius)
    bottom = gap[gap < gap[0] + a.radius]
    line = f"{cycle},{np.median(bottom) * 1e6:.1f},{np.percentile(gap[:300], 10) * 1e6:.1f},{len(bottom)}"
    if truth and cycle in truth[0]:
        off = np.nanmean(x[k], axis=0) - truth[1][truth[0].index(cycle)].mean(axis=0)
        offsets.append(off[2])
        line += "," + ",".join(f"{v * 1e6:.1f}" for v in off)
    print(line)
if a.lower:
    if not offsets:
        raise SystemExit("floor_offset: --lower needs --truth with frames of the store's cycles")
    shutil.copy(a.store, a.lower)
    with h5py.File(a.lower, "r+") as f:
        v = f["particles/grains/position/value"]
        moved = v[...]
        moved[:, :, 2] -= np.mean(offsets) / scale
        v[...] = moved
    print(f"# wrote {a.lower}, lowered by {np.mean(offsets) * 1e6:.1f} um")
