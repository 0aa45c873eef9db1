#!/usr/bin/env python3
"""A copy of a DEM run whose frame of CYCLE carries the errors its tracked scans have there
(each grain's tracked centre less its true one), or a part of them, so that a twin placed
from it starts where the scans put the grains while the window's frames stay exact
(docs/CALIBRATION.md, "What placing from the scans does to the twin"). MODE:
  scans      the scans' errors, as they are;
  shift      their mean alone (a registration's offset);
  smooth     each grain's error averaged over the grains within 2 d (the errors' smooth part);
  clipped    the errors beyond 3 robust standard deviations (per axis) redrawn normal (seed 7);
  projected  the scans' errors, then every pair overlapping by more than the truth's 99th
             percentile of overlaps pushed back to it, both grains alike (Jacobi sweeps).
Usage: scripts/frame_with_scan_errors.py TRACKS.h5 DEM.h5 OUT.h5 CYCLE MODE
       (PYTHONPATH=build/python)"""
import shutil
import sys

import granmem
import h5py
import numpy as np
from scipy.spatial import cKDTree

SCALE = {"m": 1.0, "mm": 1e3}  # the stored unit per metre


def scan_errors(tracks, truth, cycle, diameter):
    """Each true grain's tracked centre less its own (m), and which grains were tracked."""
    run = granmem.read_run(tracks)
    found = np.asarray(run["position"][list(run["step"]).index(cycle)])
    seen = np.all(np.isfinite(found), 1)
    dist, idx = cKDTree(truth).query(np.where(seen[:, None], found, 1e9))
    ok = seen & (dist < 0.2 * diameter)
    err, has = np.zeros_like(truth), np.zeros(len(truth), bool)
    err[idx[ok]], has[idx[ok]] = (found - truth[idx])[ok], True
    return err, has


def pushed_apart(x, truth, diameter, sweeps=200):
    pairs = cKDTree(truth).query_pairs(1.01 * diameter, output_type="ndarray")
    overlap = diameter - np.linalg.norm(truth[pairs[:, 0]] - truth[pairs[:, 1]], axis=1)
    reach = diameter - np.percentile(overlap[overlap > 0], 99)
    x = x.copy()
    for _ in range(sweeps):
        pairs = cKDTree(x).query_pairs(reach, output_type="ndarray")
        if len(pairs) == 0:
            break
        u = x[pairs[:, 1]] - x[pairs[:, 0]]
        r = np.linalg.norm(u, axis=1)
        step = u / r[:, None] * ((reach - r) / 2 * 1.01)[:, None]
        moved = np.zeros_like(x)
        np.add.at(moved, pairs[:, 0], -step)
        np.add.at(moved, pairs[:, 1], step)
        x += moved
    return x


def placed(mode, truth, err, has, diameter):
    if mode == "shift":
        return truth + err[has].mean(0)
    if mode == "smooth":
        near = cKDTree(truth[has]).query_ball_point(truth, 2 * diameter)
        return truth + np.array([err[has][n].mean(0) for n in near])
    if mode == "clipped":
        median = np.median(err[has], 0)
        sigma = 1.4826 * np.median(np.abs(err[has] - median), 0)
        wild = has[:, None] & (np.abs(err - median) > 3 * sigma)
        drawn = median + np.random.default_rng(7).normal(size=err.shape) * sigma
        err = np.where(wild, drawn, err)
    x = np.where(has[:, None], truth + err, truth)
    if mode == "projected":
        return pushed_apart(x, truth, diameter)
    if mode in ("scans", "clipped"):
        return x
    raise SystemExit(f"frame_with_scan_errors.py: unknown mode '{mode}'")


def main():
    tracks, dem, out, cycle, mode = sys.argv[1:6]
    cycle = int(cycle)
    shutil.copy(dem, out)
    with h5py.File(out, "r+") as f:
        position = f["/particles/grains/position/value"]
        unit = position.attrs.get("unit", b"m")
        scale = SCALE[unit.decode() if isinstance(unit, bytes) else unit]
        k = list(f["/particles/grains/position/step"][...]).index(cycle)
        truth = position[k] / scale
        diameter = 2 * np.nanmedian(f["/particles/grains/radius"][...]) / scale
        err, has = scan_errors(tracks, truth, cycle, diameter)
        x = placed(mode, truth, err, has, diameter)
        print(f"{mode}: mean moved {np.mean(x - truth, 0) * 1e6} um, "
              f"RMS {np.sqrt(np.mean((x - truth) ** 2, 0)) * 1e6} um")
        position[k] = x * scale


if __name__ == "__main__":
    main()
