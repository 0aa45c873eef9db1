#!/usr/bin/env python3
"""A placed twin's fit made again offline from calibrate's outputs, to try what the scans'
placing does to it (docs/CALIBRATION.md, "Placed from scans: what one scan's errors do to
the twin"): a cubic in ln mu_s through each observable's runs (steady_state_runs.csv), and
mu_s where the chi-square of the experiment's values against it is least, each observable
weighted by one packing's scatter and the experiment's systematic error (summary.json), on
a grid; diagonal, without the fit's covariance or cross-validation, so it is a comparison,
not the fit.

  scripts/scanned_fit_offline.py FIT_DIR [MOVED_FIT_DIR]

prints the fit as is; the placement probe's effect (summary.json placement_probe) taken as an
offset of the experiment instead of an error; and, given the fit of the same design whose
refined packings were each moved by a draw of the scans' error (MOVED_FIT_DIR, the same
frictions), the fit on all runs with and without Richardson's extrapolation to no error:
each run less the moved packings' mean less the unmoved refined packings', once per draw it
was placed with (design and unmoved refined once, moved twice).
"""
import json
import sys

import numpy as np
import pandas as pd

DESIGN_FRICTIONS = (0.05, 0.13, 0.35, 0.6)  # a placed twin's default design


def fitted(summary, runs, names):
    return [n for n in names if n in runs and summary["observables"].get(n, {}).get("experiment")
            is not None and n not in (summary.get("left_out_for_scan_noise") or [])]


def least_chi2(x, values, experiment, variance):
    grid = np.linspace(x.min(), x.max(), 4000)
    chi2 = sum((np.polyval(np.polyfit(x, values[n], 3), grid) - experiment[n]) ** 2 / variance[n]
               for n in experiment)
    return float(np.exp(grid[np.argmin(chi2)]))


def main(args):
    folder = args[0]
    summary = json.load(open(f"{folder}/summary.json"))
    runs = pd.read_csv(f"{folder}/steady_state_runs.csv", comment="#")
    names = fitted(summary, runs, summary["observables"])
    moved = None
    if len(args) > 1:
        moved = pd.read_csv(f"{args[1]}/steady_state_runs.csv", comment="#")
        names = [n for n in names if n in moved]
    obs = summary["observables"]
    experiment = {n: obs[n]["experiment"] for n in names}
    variance = {n: obs[n]["packing_scatter"] ** 2 + obs[n].get("experiment_systematic", 0) ** 2
                for n in names}
    x = np.log(runs.mu_s.values)
    values = {n: runs[n].values for n in names}
    true = summary.get("mu_s_true")
    line = lambda label, mu: f"{label} {mu:.4f}" + (f" ({100 * (mu / true - 1):+.1f} %)" if true else "")
    out = [line("as is", least_chi2(x, values, experiment, variance))]
    probe = summary.get("placement_probe", {}).get("less_source", {})
    if probe:
        offset = {n: experiment[n] + probe.get(n, 0.0) for n in names}
        out.append(line("probe as offset", least_chi2(x, values, offset, variance)))
    if moved is not None:
        unmoved_refined = runs[~runs.mu_s.isin(DESIGN_FRICTIONS)]
        moved_refined = moved[~moved.mu_s.isin(DESIGN_FRICTIONS)]
        both_x = np.r_[x, np.log(moved_refined.mu_s.values)]
        both = {n: np.r_[values[n], moved_refined[n].values] for n in names}
        out.append(line("all runs", least_chi2(both_x, both, experiment, variance)))
        draw = {n: moved_refined[n].mean() - unmoved_refined[n].mean() for n in names}
        extrapolated = {n: np.r_[values[n] - draw[n], moved_refined[n].values - 2 * draw[n]]
                        for n in names}
        out.append(line("Richardson", least_chi2(both_x, extrapolated, experiment, variance)))
    print(f"{folder}: true {true}; " + "; ".join(out))


if __name__ == "__main__":
    if not sys.argv[1:]:
        sys.exit(__doc__)
    main(sys.argv[1:])
