#!/usr/bin/env python3
"""A checkpoint's grains moved by a normal draw (each coordinate, RMS in metres), its contact
history, velocities and forces kept: a replica of a run that keeps its history
(docs/CALIBRATION.md, "The contact history a placed twin loses").
Usage: scripts/move_state.py STATE.h5 OUT.h5 SEED RMS_M"""
import shutil
import sys

import h5py
import numpy as np

state, out, seed, rms = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
tmp = out + ".tmp"
shutil.copy(state, tmp)
with h5py.File(tmp, "r+") as f:
    p = f["checkpoint/grains/position"]
    if p.attrs.get("unit", b"m") not in (b"m", "m"):
        sys.exit(f"{state}: positions not in metres")
    p[...] = p[...] + np.random.default_rng(seed).normal(size=p.shape) * rms
shutil.move(tmp, out)
