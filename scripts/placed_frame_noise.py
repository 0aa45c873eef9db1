"""A copy of a simulated run whose centres are moved as a scan's are: by a normal locating
error (ACROSS_UM across the slices, ALONG_Z_UM along z) and, optionally, pulled towards
their near neighbours as locate's fits are (docs/CALIBRATION.md, "What the scans' centres
share"): by PULL_XY_UM and PULL_Z_UM per unit vector to each neighbour, weighted by
exp(-gap / (WIDTH d)) (WIDTH 0.05 by default). CYCLE: the one frame moved (the others
exact: a placed twin started there starts from a scan's errors while the window's
observables stay the DEM's, "The wall's force read beside the scans"), or "all".
--shift X,Y,Z (um): every centre moved by it too (a registration's offset).
Usage: /usr/bin/python3 scripts/placed_frame_noise.py RUN.h5 OUT.h5 CYCLE|all ACROSS_UM ALONG_Z_UM SEED
           [PULL_XY_UM PULL_Z_UM [WIDTH]] [--shift X,Y,Z]"""
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
    args = sys.argv[1:]
    shift = np.zeros(3)
    if "--shift" in args:
        k = args.index("--shift")
        shift = np.array([float(v) for v in args[k + 1].split(",")]) * 1e-6
        del args[k:k + 2]
    src, dst, which = args[0], args[1], args[2]
    across, along_z, seed = float(args[3]), float(args[4]), int(args[5])
    pull = np.array([float(args[6]), float(args[6]), float(args[7])]) * 1e-6 \
        if len(args) > 7 else np.zeros(3)
    width = float(args[8]) if len(args) > 8 else 0.05
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
            position[k] = as_scanned(x, diameter, sigma, pull * SCALE[unit], rng, width) \
                + shift * SCALE[unit]
    print(f"{dst}: {len(frames)} frame(s) ({x.shape[0]} grains) moved by {across}, {along_z} um"
          + (f", pulled {pull[0] * 1e6:.3g}, {pull[2] * 1e6:.3g} um towards neighbours"
             if pull.any() else "")
          + (f", shifted by {', '.join(f'{v * 1e6:.3g}' for v in shift)} um" if shift.any() else ""))


if __name__ == "__main__":
    main()
