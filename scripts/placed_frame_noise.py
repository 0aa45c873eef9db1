"""A copy of a simulated run whose centres are moved as a scan's are: by a normal locating
error (ACROSS_UM across the slices, ALONG_Z_UM along z) and, optionally, pulled towards
their near neighbours as locate's fits are (docs/CALIBRATION.md, "What the scans' centres
share"): by PULL_XY_UM and PULL_Z_UM per unit vector to each neighbour, weighted by
exp(-gap / (WIDTH d)) (WIDTH 0.05 by default). CYCLE: the one frame moved (the others
exact: a placed twin started there starts from a scan's errors while the window's
observables stay the DEM's, "The wall's force read beside the scans"), or "all".
Usage: /usr/bin/python3 scripts/placed_frame_noise.py RUN.h5 OUT.h5 CYCLE|all ACROSS_UM ALONG_Z_UM SEED
           [PULL_XY_UM PULL_Z_UM [WIDTH]]"""
import shutil
import sys

import h5py
import numpy as np
from scipy.spatial import cKDTree

SCALE = {"m": 1.0, "cm": 1e2, "mm": 1e3, "um": 1e6}  # the stored unit per metre


def towards_neighbours(x, diameter, width=0.05):
    """Each centre's sum of unit vectors to its neighbours within 1.3 d, weighted by
    exp(-gap / (width d))."""
    pairs = cKDTree(x).query_pairs(1.3 * diameter, output_type="ndarray")
    u = x[pairs[:, 1]] - x[pairs[:, 0]]
    r = np.linalg.norm(u, axis=1)
    u *= (np.exp(-(r / diameter - 1) / width) / r)[:, None]
    f = np.zeros_like(x)
    np.add.at(f, pairs[:, 0], u)
    np.add.at(f, pairs[:, 1], -u)
    return f


def as_scanned(x, diameter, noise, pull, rng, width=0.05):
    """Centres `x` moved by a normal error `noise` (x, y, z) and pulled by `pull` per unit
    vector to their neighbours, all in x's unit."""
    moved = x + rng.normal(size=x.shape) * noise
    if np.any(pull):
        moved += towards_neighbours(x, diameter, width) * pull
    return moved


def main():
    src, dst, which = sys.argv[1], sys.argv[2], sys.argv[3]
    across, along_z, seed = float(sys.argv[4]), float(sys.argv[5]), int(sys.argv[6])
    pull = np.array([float(sys.argv[7]), float(sys.argv[7]), float(sys.argv[8])]) * 1e-6 \
        if len(sys.argv) > 8 else np.zeros(3)
    width = float(sys.argv[9]) if len(sys.argv) > 9 else 0.05
    shutil.copy(src, dst)
    rng = np.random.default_rng(seed)
    with h5py.File(dst, "r+") as f:
        position = f["/particles/grains/position/value"]
        unit = position.attrs.get("unit", b"m")
        unit = unit.decode() if isinstance(unit, bytes) else unit
        steps = f["/particles/grains/position/step"][...]
        frames = range(len(steps)) if which == "all" else \
            [int(np.nonzero(steps == int(which))[0][0])]
        diameter = 2 * np.nanmedian(f["/particles/grains/radius"][...])
        sigma = np.array([across, across, along_z]) * 1e-6 * SCALE[unit]
        for k in frames:
            x = position[k]
            position[k] = as_scanned(x, diameter, sigma, pull * SCALE[unit], rng, width)
    print(f"{dst}: {len(frames)} frame(s) ({x.shape[0]} grains) moved by {across}, {along_z} um"
          + (f", pulled {pull[0] * 1e6:.3g}, {pull[2] * 1e6:.3g} um towards neighbours"
             if pull.any() else ""))


if __name__ == "__main__":
    main()
