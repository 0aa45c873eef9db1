#!/usr/bin/env python3
"""Whether the frames between the preparation and the window carry friction the window does
not (docs/CALIBRATION.md, "How wide the intervals are against the errors"): for a twin
placed from the scans' preparation, the packing's height (packing fraction from the end
layers' mean, as packing_structure.cpp measures it) in every frame of each twin run and of
the pseudo-experiment's exact frames, fitted as scripts/refit_offline.py fits (its GLS,
cross-validation and t) with the window's mean and the frame before it, then also the mean
over the earlier frames (cycles 1 to the window's first - 2), then those split in three.
Exact positions on both sides: what the frames hold, before any scan's error.

  scripts/heights_frame_by_frame.py FIT_DIR PSEUDO.h5 [FIT_DIR PSEUDO.h5 ...]

FIT_DIR: calibrate's output (summary.json with mu_s_true, steady_state_runs.csv, runs/);
PSEUDO.h5: the pseudo-experiment the scans were drawn from. Prints a CSV line per case and
variant, and a summary line per variant. Needs build/python on PYTHONPATH.
"""
import csv
import json
import sys

import numpy as np

import granmem
from refit_offline import fit

VARIANTS = {"window_and_before": 0, "earlier_mean": 1, "earlier_in_three": 3}


def height_packing_fraction(position, radius, section):
    seen = np.isfinite(position).all(axis=1)
    position, radius = position[seen], radius[seen]
    typical = np.median(radius)
    layer = max(1, int(round(section / (16 * typical * typical))))
    bottom = np.sort(position[:, 2] - radius)[:layer].mean()
    top = -np.sort(-(position[:, 2] + radius))[:layer].mean()
    return 4 / 3 * np.pi * np.sum(radius ** 3) / (section * (top - bottom))


def heights(path):
    """Cycle and height per frame; the grains of the typical radius (a lid or wall body
    stored as a particle left out)."""
    run = granmem.read_run(path)
    low, high = run["box"]
    section = (high[0] - low[0]) * (high[1] - low[1])
    radius = np.asarray(run["radius"])
    grain = np.isclose(radius, np.median(radius))
    return np.asarray(run["step"]), np.array(
        [height_packing_fraction(p[grain], radius[grain], section) for p in run["position"]])


def observables(cycles, h, first, last, parts):
    columns = [h[..., (cycles >= first) & (cycles <= last)].mean(-1),
               h[..., cycles == first - 1][..., 0]]
    earlier = np.where((cycles >= 1) & (cycles <= first - 2))[0]
    if parts and len(earlier):
        for part in np.array_split(earlier, min(parts, len(earlier))):
            columns.append(h[..., part].mean(-1))
    return np.stack(columns, -1)


def main():
    if len(sys.argv) < 3 or len(sys.argv) % 2 == 0:
        sys.exit(__doc__)
    print("folder,true_mu_s,variant,mu_s,low,high,width")
    results = {v: [] for v in VARIANTS}
    for folder, pseudo in zip(sys.argv[1::2], sys.argv[2::2]):
        summary = json.load(open(f"{folder}/summary.json"))
        first, last = summary["window"]
        truth = summary["mu_s_true"]
        rows = list(csv.DictReader(l for l in open(f"{folder}/steady_state_runs.csv")
                                   if not l.startswith("#")))
        runs = [heights(f"{folder}/runs/mu_s_{r['mu_s']}_seed_{int(float(r['seed']))}.h5")
                for r in rows]
        cycles = runs[0][0]
        twin = np.array([h for _, h in runs])
        cycles_e, experiment = heights(pseudo)
        x = np.log([float(r["mu_s"]) for r in rows])
        seeds = np.array([int(float(r["seed"])) for r in rows])
        for name, parts in VARIANTS.items():
            values = observables(cycles, twin, first, last, parts)
            target = observables(cycles_e, experiment, first, last, parts)
            f = fit(x, seeds, values, target, np.zeros(values.shape[1]), 3)
            results[name].append((truth, f["mu_s"], f["low"], f["high"]))
            print(f"{folder},{truth},{name},{f['mu_s']:.4f},{f['low']:.4f},{f['high']:.4f},"
                  f"{f['high'] - f['low']:.4f}")
    for name, r in results.items():
        truth, mu, low, high = np.array(r).T
        holds = (low <= truth) & (truth <= high)
        bar = holds & (high - low <= 0.08) & (np.abs(mu - truth) <= 0.02)
        print(f"# {name}: {holds.sum()} of {len(r)} hold, {bar.sum()} meet the bar, mean "
              f"width {np.mean((high - low) / truth):.3f} of mu_s, RMS error "
              f"{np.sqrt(np.mean(np.log(mu / truth) ** 2)):.3f} in ln mu_s")


if __name__ == "__main__":
    main()
