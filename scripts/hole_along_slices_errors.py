#!/usr/bin/env python3
"""Tracked scans' centres against the DEM run they were rendered from, at one frame: the RMS
error along x, y and z (the common offset removed), the z error of the grains whose hole runs
along the slices (|axis z| < 0.1) against the others', how many centres err by more than
25 um along z, and the touching pairs' distance error (docs/BENCHMARKS.md, "Centres locked to
the slices by a hole along them"). A store with one frame (a single scan tracked) is read at
its first.
Usage: scripts/hole_along_slices_errors.py DEM.h5 CYCLE TRACKS.h5 [TRACKS.h5 ...]
       (PYTHONPATH=build/python)"""
import sys

import granmem
import numpy as np
from scipy.spatial import cKDTree


def frame(run, step):
    steps = list(run["step"])
    return np.asarray(run["position"][steps.index(step) if step in steps else 0])


def main():
    dem, step = granmem.read_run(sys.argv[1]), int(sys.argv[2])
    truth = frame(dem, step)
    axis = np.asarray(dem["axis"][list(dem["step"]).index(step)])
    d = 2 * np.nanmedian(dem["radius"])
    for path in sys.argv[3:]:
        tracked = frame(granmem.read_run(path), step)
        seen = np.all(np.isfinite(tracked), 1)
        dist, idx = cKDTree(truth).query(np.where(seen[:, None], tracked, 1e9))
        ok = seen & (dist < 0.2 * d)
        true, found = truth[idx][ok], tracked[ok]
        e = (found - true) * 1e6
        e -= np.median(e, 0)
        along = np.abs(axis[idx][ok][:, 2]) < 0.1
        pairs = cKDTree(true).query_pairs(1.01 * d, output_type="ndarray")
        apart = (np.linalg.norm(found[pairs[:, 0]] - found[pairs[:, 1]], axis=1)
                 - np.linalg.norm(true[pairs[:, 0]] - true[pairs[:, 1]], axis=1)) * 1e6
        rms = np.sqrt(np.mean(e**2, 0))
        print(f"{path}: RMS x / y / z {rms[0]:.2f} / {rms[1]:.2f} / {rms[2]:.2f} um; z of the "
              f"{along.sum()} holes along the slices {np.sqrt(np.mean(e[along, 2]**2)):.1f} um, "
              f"the others' {np.sqrt(np.mean(e[~along, 2]**2)):.1f}; "
              f"{np.sum(np.abs(e[:, 2]) > 25)} beyond 25 um along z; {len(apart)} touching pairs "
              f"read {apart.mean():+.2f} um apart, RMS {np.sqrt(np.mean(apart**2)):.2f}, "
              f"{np.sum(np.abs(apart) > 25)} beyond 25 um")


if __name__ == "__main__":
    main()
