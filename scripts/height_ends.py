#!/usr/bin/env python3
"""The packing fraction from the packing's height, its ends taken two ways: the extreme
grains (the lowest bottom, the highest top) and the end layers (the mean over a quarter of
a layer's grains, the cross-section over 4 d^2, as granmem's height_packing_fraction), each
with the grains' count and radius given, as calibrate measures an experiment (a scan's
located radii come out small). Over a window of cycles: for a twin's runs, the packing-to-
packing scatter (pooled over frictions) and the slope per unit of ln mu_s; for scans and the
DEM positions they were drawn from, both values side by side.

    PYTHONPATH=build/python scripts/height_ends.py --window 37:40 --grains 1500 --radius 2.5e-3 \
        --runs out/ss40/runs --pair SCANS.h5 out/ss40/pseudo_0.15_seed_7.h5
"""
import argparse
import glob
import re

import numpy as np

import granmem

SCALE = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}


def heights(path, window, grains, r):
    run = granmem.read_run(path)
    scale = SCALE[run["length_unit"]]
    (lo, hi) = run["box"]
    section = (hi[0] - lo[0]) * (hi[1] - lo[1]) * scale ** 2
    ends = max(1, int(round(section / (16 * r * r))))
    out = {"extreme": [], "end layers": []}
    for t, step in enumerate(run["step"]):
        if not window[0] <= step <= window[1]:
            continue
        z = run["position"][t, :, 2] * scale
        z = np.sort(z[np.isfinite(z)])
        volume = grains * 4 / 3 * np.pi * r ** 3
        out["extreme"].append(volume / (section * (z[-1] - z[0] + 2 * r)))
        out["end layers"].append(volume / (section * (z[-ends:].mean() - z[:ends].mean() + 2 * r)))
    return {k: float(np.mean(v)) for k, v in out.items()}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--window", required=True)
    p.add_argument("--grains", type=int, required=True)
    p.add_argument("--radius", type=float, required=True, help="every grain's, m")
    p.add_argument("--runs", help="a twin's runs/ folder (mu_s_M_seed_S.h5)")
    p.add_argument("--pair", nargs=2, metavar=("SCANS", "DEM"))
    a = p.parse_args()
    window = tuple(int(c) for c in a.window.split(":"))
    if a.runs:
        by_mu = {}
        for path in sorted(glob.glob(a.runs + "/mu_s_*_seed_*.h5")):
            mu = float(re.search(r"mu_s_([0-9.]+)_seed_", path).group(1))
            by_mu.setdefault(mu, []).append(heights(path, window, a.grains, a.radius))
        mus = sorted(by_mu)
        for key in ("extreme", "end layers"):
            values = {mu: [h[key] for h in by_mu[mu]] for mu in mus}
            scatter = np.sqrt(np.mean([np.var(v, ddof=1) for v in values.values() if len(v) > 1]))
            means = [np.mean(values[mu]) for mu in mus]
            slope = np.polyfit(np.log(mus), means, 1)[0]
            print(f"twin, {key}: scatter {scatter:.5f}, slope {slope:.5f} per ln mu_s, "
                  f"means {' '.join(f'{m:.4f}' for m in means)}")
    if a.pair:
        scans, dem = (heights(path, window, a.grains, a.radius) for path in a.pair)
        for key in ("extreme", "end layers"):
            print(f"{key}: scans {scans[key]:.5f}, DEM {dem[key]:.5f}, "
                  f"difference {scans[key] - dem[key]:+.5f}")


if __name__ == "__main__":
    main()
