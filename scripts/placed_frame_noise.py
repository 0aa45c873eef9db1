"""A copy of a simulated run whose frame of one cycle has every centre moved by a normal
locating error (across the slices, along z; um), the other frames exact: a placed twin
started there starts from a scan's errors while the window's observables stay the DEM's
(docs/CALIBRATION.md, "The wall's force read beside the scans").
Usage: /usr/bin/python3 scripts/placed_frame_noise.py RUN.h5 OUT.h5 CYCLE ACROSS_UM ALONG_Z_UM SEED"""
import shutil
import sys

import h5py
import numpy as np

SCALE = {"m": 1.0, "cm": 1e2, "mm": 1e3, "um": 1e6}  # the stored unit per metre
src, dst, cycle = sys.argv[1], sys.argv[2], int(sys.argv[3])
across, along_z, seed = float(sys.argv[4]), float(sys.argv[5]), int(sys.argv[6])
shutil.copy(src, dst)
with h5py.File(dst, "r+") as f:
    position = f["/particles/grains/position/value"]
    unit = position.attrs.get("unit", b"m")
    unit = unit.decode() if isinstance(unit, bytes) else unit
    k = int(np.nonzero(f["/particles/grains/position/step"][...] == cycle)[0][0])
    sigma = np.array([across, across, along_z]) * 1e-6 * SCALE[unit]
    x = position[k]
    position[k] = x + np.random.default_rng(seed).normal(size=x.shape) * sigma
print(f"{dst}: frame of cycle {cycle} ({x.shape[0]} grains) moved by {across}, {along_z} um")
