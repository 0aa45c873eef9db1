#!/usr/bin/env python3
"""A calibrate twin's runs, one line per friction: the window mean of each cycle's mean
end-of-cycle displacement |dr| / d (drift removed, grains more than 1 d inside the packing's
extent) and the bulk contact fabric's anisotropy along the driven wall (y) less across it (x)
and vertical less horizontal (contacts within 1.02 d, grains 2 d inside), with their scatter
over the friction's packings; then the experiment's (docs/CALIBRATION.md, "The end-of-cycle
displacement on a placed twin").
Usage: scripts/twin_runs_motion.py RUNS_DIR FIRST:LAST [EXPERIMENT.h5]"""
import glob
import re
import sys

import h5py
import numpy as np
from scipy.spatial import cKDTree


def frames(path):
    with h5py.File(path, "r") as f:
        g = f["particles/grains"]
        unit = g["position/value"].attrs.get("unit", b"m")
        scale = {"m": 1.0, "mm": 1e-3}[unit.decode() if isinstance(unit, bytes) else unit]
        return (g["position/value"][...] * scale, list(g["position/step"][...]),
                2 * np.nanmedian(g["radius"][...]) * scale)


def inside(p, margin):
    lo, hi = np.nanmin(p, 0) + margin, np.nanmax(p, 0) - margin
    return np.all((p > lo) & (p < hi), axis=1)


def touching_pairs(p, d):
    """The finite centres of a frame and their pairs closer than `d` (index pairs)."""
    p = p[np.all(np.isfinite(p), axis=1)]
    return p, cKDTree(p).query_pairs(d, output_type="ndarray")


def cycle_dr(pos, step, d, c):
    """Cycle c's mean end-of-cycle |dr| / d, drift removed, grains 1 d inside the extent."""
    a, b = pos[step.index(c - 1)], pos[step.index(c)]
    ok = inside(a, d) & np.all(np.isfinite(b), axis=1)
    u = (b[ok] - a[ok]) / d
    return np.linalg.norm(u - u.mean(0), axis=1).mean()


def motion(path, first, last):
    pos, step, d = frames(path)
    dr, yx, zh = [], [], []
    for c in range(first, last + 1):
        dr.append(cycle_dr(pos, step, d, c))
        p, pairs = touching_pairs(pos[step.index(c)], 1.02 * d)
        bulk = inside(p, 2 * d)
        pairs = pairs[bulk[pairs[:, 0]] | bulk[pairs[:, 1]]]
        n = p[pairs[:, 1]] - p[pairs[:, 0]]
        n /= np.linalg.norm(n, axis=1)[:, None]
        f = n.T @ n / len(n)
        yx.append(f[1, 1] - f[0, 0])
        zh.append(f[2, 2] - 0.5 * (f[0, 0] + f[1, 1]))
    return np.mean(dr), np.mean(yx), np.mean(zh)


def main():
    first, last = map(int, sys.argv[2].split(":"))
    runs = {}
    for path in glob.glob(sys.argv[1] + "/mu_s_*_seed_*.h5"):
        mu = float(re.search(r"mu_s_([0-9.]+)_seed_", path).group(1))
        runs.setdefault(mu, []).append(motion(path, first, last))
    print("mu_s,packings,dr,dr_sd,fabric_yy_xx,fabric_yy_xx_sd,fabric_zz_h,fabric_zz_h_sd")
    for mu in sorted(runs):
        v = np.array(runs[mu])
        sd = v.std(0, ddof=1) if len(v) > 1 else np.full(3, np.nan)
        print(f"{mu},{len(v)},{v[:, 0].mean():.5f},{sd[0]:.5f},{v[:, 1].mean():+.4f},{sd[1]:.4f},"
              f"{v[:, 2].mean():+.4f},{sd[2]:.4f}")
    if len(sys.argv) > 3:
        e = motion(sys.argv[3], first, last)
        print(f"experiment,1,{e[0]:.5f},,{e[1]:+.4f},,{e[2]:+.4f},")


if __name__ == "__main__":
    main()
