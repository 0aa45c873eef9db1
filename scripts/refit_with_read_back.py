#!/usr/bin/env python3
"""What-if refits of a placed twin's steady-state fit (docs/CALIBRATION.md, "The placed
packing's read-back as a systematic error"): the runs' window means (FIT_DIR/steady_state_runs.csv)
against the experiment's (FIT_DIR/summary.json), refitted as observable_fit.cpp fits them (a
polynomial trend in ln mu_s, the runs' covariance about it shrunk to its diagonal, the trend's
leverage, the misfit's widening; without the cross-validation) three ways: the experiment as
measured, its values moved by the placed packing's read-back (an offset that would persist into
the window), and the read-back's size as each value's systematic error. One CSV line each.
Usage: scripts/refit_with_read_back.py [--degree 3] FIT_DIR ..."""
import json
import sys

import numpy as np
from scipy import optimize, stats


def load(folder):
    rows = [l for l in open(folder + "/steady_state_runs.csv") if not l.startswith("#")]
    names = rows[0].strip().split(",")[2:]
    data = np.array([[float(x) for x in r.split(",")] for r in rows[1:]])
    s = json.load(open(folder + "/summary.json"))
    experiment = np.array([s["observables"][n]["experiment"] for n in names])
    read_back = s.get("placed_frame_less_experiment", {})
    return data[:, 0], data[:, 2:], experiment, np.array([read_back.get(n, 0.0) for n in names]), s


def fit(mu, values, experiment, degree, systematic):
    x = np.log(mu)
    centre = x.mean()
    runs, m = values.shape
    powers = lambda v: np.vander(np.atleast_1d(v - centre), degree + 1, increasing=True)
    design = powers(x)
    normal_inverse = np.linalg.inv(design.T @ design)
    coefficients = normal_inverse @ design.T @ values
    spare = runs - (degree + 1)
    residual = values - design @ coefficients
    sample = residual.T @ residual / spare
    shrink = m / (m + spare)
    covariance = (1 - shrink) * sample
    np.fill_diagonal(covariance, np.diag(sample))
    covariance += np.eye(m) * 1e-12 * np.diag(sample).max()

    def c_at(v):
        p = powers(v)[0]
        return (1 + p @ normal_inverse @ p) * covariance + np.diag(systematic**2)

    predict = lambda v: powers(v)[0] @ coefficients
    chi2 = lambda v: (predict(v) - experiment) @ np.linalg.solve(c_at(v), predict(v) - experiment)
    grid = np.linspace(x.min(), x.max(), 49)
    start = grid[np.argmin([chi2(v) for v in grid])]
    best = optimize.minimize_scalar(chi2, method="bounded",
                                    bounds=(max(x.min(), start - 0.2), min(x.max(), start + 0.2))).x
    slope = (predict(best + 1e-4) - predict(best - 1e-4)) / 2e-4
    sigma = np.sqrt(1 / (slope @ np.linalg.solve(c_at(best), slope)))
    sigma *= max(1.0, np.sqrt(chi2(best) / (m - 1)))
    t = stats.t.ppf(0.975, spare)
    return np.exp(best), np.exp(best - t * sigma), np.exp(best + t * sigma), chi2(best)


args = sys.argv[1:]
degree = 3
if args[:1] == ["--degree"]:
    degree, args = int(args[1]), args[2:]
print("fit,true_mu_s,refit,mu_s,ci95_low,ci95_high,chi2")
for folder in args:
    mu, values, experiment, read_back, s = load(folder)
    for label, target, systematic in [("as measured", experiment, 0 * read_back),
                                      ("moved by the read-back", experiment + read_back, 0 * read_back),
                                      ("read-back as systematic error", experiment, np.abs(read_back))]:
        f, lo, hi, c = fit(mu, values, target, degree, systematic)
        print(f"{folder},{s.get('mu_s_true')},{label},{f:.4g},{lo:.4g},{hi:.4g},{c:.3g}")
