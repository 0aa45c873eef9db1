#!/usr/bin/env python3
"""A steady-state fit made again offline from calibrate's outputs, as observable_fit.cpp
makes it, to ask what one observable adds on the same runs (docs/CALIBRATION.md, "The
packing's height before the window"): each observable's window means over the twin's runs
(FIT_DIR/steady_state_runs.csv) a polynomial in ln mu_s (the degree summary.json's method
names), the runs' covariance about it shrunk to its diagonal by m / (m + spare runs), the
experiment's values and systematic errors (summary.json) at (1 + leverage) times it plus the
systematic variances; mu_s where the generalized chi-square is least; its error from the
Fisher information, widened by sqrt(chi2 / dof) on a misfit; the cross-validation across
packings (each interior run fitted from the other seeds' runs, its error over the trend's
predicted error there, the RMS ratio carried to the fit) where larger, with the systematic
share beside it; Student's t for the spare or held-out runs. It reproduces calibrate's
interval to ~1e-4 on the scanned cases; it is a check, not the fit.

  scripts/refit_offline.py FIT_DIR [--without NAME[,NAME]] ...
  scripts/refit_offline.py --calibration [--null DRAWS [--bootstrap]] FIT_DIR ...

prints, per folder: the truth, calibrate's fit, and this one (with NAMEs left out). With
--calibration, how honest the interval is (docs/CALIBRATION.md, "How wide the intervals are
against the errors"): the fit's error in ln mu_s over the GLS sigma (the Fisher information
of the runs' covariance, with the systematic errors) and over the interval's, and the
held-out runs' ratios (the cross-validation's) split into the design's packings and the
refined ones; --null adds the same from Gaussian draws about the fitted trend with the shrunk
covariance (--bootstrap: the runs' own residuals resampled), where the experiment is by
construction one more packing.
"""
import argparse
import csv
import json
import re

import numpy as np
from scipy import stats


class Trend:
    def __init__(self, x, values, degree):
        self.degree = degree
        design = np.vander(x, degree + 1)
        self.coef, *_ = np.linalg.lstsq(design, values, rcond=None)
        residual = values - design @ self.coef
        self.spare = len(x) - degree - 1
        sample = residual.T @ residual / self.spare
        m = values.shape[1]
        shrink = m / (m + self.spare)
        self.cov = (1 - shrink) * sample
        np.fill_diagonal(self.cov, np.diag(sample))
        self.inverse_gram = np.linalg.inv(design.T @ design)

    def row(self, g):
        return np.vander([g], self.degree + 1)[0]

    def predict(self, g):
        return self.row(g) @ self.coef

    def slope(self, g):
        d = self.degree
        return np.array([(d - k) * g ** (d - k - 1) if d > k else 0.0
                         for k in range(d + 1)]) @ self.coef

    def covariance(self, g, systematic2):
        leverage = self.row(g) @ self.inverse_gram @ self.row(g)
        return (1 + leverage) * self.cov + np.diag(systematic2)

    def variance(self, g, systematic2):
        s = self.slope(g)
        return 1 / (s @ np.linalg.solve(self.covariance(g, systematic2), s))


def least_chi2(x, values, target, systematic2, degree):
    trend = Trend(x, values, degree)

    def chi2(g):
        d = trend.predict(g) - target
        return d @ np.linalg.solve(trend.covariance(g, systematic2), d)

    grid = np.linspace(x.min(), x.max(), 1201)
    best = min(grid, key=chi2)
    step = grid[1] - grid[0]
    fine = np.linspace(max(best - step, x.min()), min(best + step, x.max()), 201)
    best = min(fine, key=chi2)
    return trend, best, chi2(best)


def held_out_ratios(x, seeds, values, degree, trend):
    """Each interior run fitted from the other seeds' runs: its error in ln mu_s over the
    error the trend through all runs predicts there, by run index."""
    none = np.zeros(values.shape[1])
    ratios = {}
    for i in range(len(x)):
        others = seeds != seeds[i]
        if others.sum() < degree + 2 or not x[others].min() < x[i] < x[others].max():
            continue
        _, held_out, _ = least_chi2(x[others], values[others], values[i], none, degree)
        ratios[i] = (held_out - x[i]) / np.sqrt(trend.variance(x[i], none))
    return ratios


def gls(x, values, target, systematic2, degree):
    """ln mu_s where the generalized chi-square is least, and its variance from the Fisher
    information, widened by chi2 / dof on a misfit (Birge)."""
    trend, g, chi2 = least_chi2(x, values, target, systematic2, degree)
    dof = len(target) - 1
    widened = max(1.0, chi2 / dof) if dof > 0 else 1.0
    return trend, g, chi2, trend.variance(g, systematic2) * widened, widened


def fit(x, seeds, values, target, systematic, degree):
    systematic2 = systematic ** 2
    trend, g, chi2, variance, widened = gls(x, values, target, systematic2, degree)
    c_inv = np.linalg.inv(trend.covariance(g, systematic2))
    s = trend.slope(g)
    weights = (s @ c_inv) / (s @ c_inv @ s)
    systematic_variance = weights @ np.diag(systematic2) @ weights * widened
    sigma, t = np.sqrt(variance), stats.t.ppf(0.975, trend.spare)
    none = np.zeros_like(systematic2)
    held_out = held_out_ratios(x, seeds, values, degree, trend)
    ratios = [r ** 2 for r in held_out.values()]
    cross_validated = np.sqrt(np.mean(ratios) * trend.variance(g, none)) if ratios else 0.0
    if ratios and cross_validated > np.sqrt(max(0.0, variance - systematic_variance)):
        sigma = np.hypot(cross_validated, np.sqrt(systematic_variance))
        t = stats.t.ppf(0.975, len(ratios))
    return {"mu_s": np.exp(g), "low": np.exp(g - t * sigma), "high": np.exp(g + t * sigma),
            "chi2": chi2, "sigma": sigma, "gls_sigma": np.sqrt(variance),
            "cross_validated": cross_validated, "trend": trend, "held_out": held_out}


def read(folder, without):
    summary = json.load(open(f"{folder}/summary.json"))
    observables = summary["observables"]
    names = [n for n, o in observables.items() if "model_at_fit" in o and n not in without]
    rows = list(csv.DictReader(l for l in open(f"{folder}/steady_state_runs.csv")
                               if not l.startswith("#")))
    x = np.log([float(r["mu_s"]) for r in rows])
    seeds = np.array([int(float(r["seed"])) for r in rows])
    values = np.array([[float(r[n]) for n in names] for r in rows])
    target = np.array([observables[n]["experiment"] for n in names])
    systematic = np.array([observables[n]["experiment_systematic"] for n in names])
    degree = int(re.search(r"degree (\d)", summary["mu_s_interval_method"]).group(1))
    return summary, (x, seeds, values, target, systematic, degree)


def refit(folder, without):
    summary, data = read(folder, without)
    return summary, fit(*data)


def design_seeds(summary, seeds):
    """The staged design's seeds (its first `replicas`); the refined packings' are the rest."""
    return np.isin(seeds, np.unique(seeds)[: summary["replicas"]])


def rms(values):
    return float(np.sqrt(np.mean(np.square(values)))) if len(values) else float("nan")


def residual_draws(x, values, trend, degree, bootstrap, rng):
    """Draws of the runs' deviations from their trend and one more packing's: Gaussian with
    the shrunk covariance, or (bootstrap) the runs' own residual vectors, each inflated by
    1 / sqrt(1 - leverage), resampled whole."""
    if bootstrap:
        design = np.vander(x, degree + 1)
        leverage = np.einsum("ij,jk,ik->i", design, trend.inverse_gram, design)
        residual = (values - design @ trend.coef) / np.sqrt(1 - leverage)[:, None]
        return lambda n: residual[rng.integers(0, len(x), n)]
    root = np.linalg.cholesky(trend.cov)
    return lambda n: rng.standard_normal((n, values.shape[1])) @ root.T


def calibration(folder, without, draws, bootstrap, rng):
    """The experiment's error in units of the GLS sigma and of the interval's, beside the
    held-out runs' (design and refined packings apart); with `draws`, the same from a null:
    runs and an experiment at the truth drawn about the fitted trend (residual_draws)."""
    summary, (x, seeds, values, target, systematic, degree) = read(folder, without)
    f = fit(x, seeds, values, target, systematic, degree)
    truth = np.log(summary["mu_s_true"])
    trend, held = f["trend"], f["held_out"]
    design = design_seeds(summary, seeds)
    error = np.log(f["mu_s"]) - truth
    row = {"z_gls": error / f["gls_sigma"], "z_interval": error / f["sigma"],
           "held_out_design": [r for i, r in held.items() if design[i]],
           "held_out_refined": [r for i, r in held.items() if not design[i]]}
    null = {"z_gls": [], "held_out_design": [], "held_out_refined": []}
    deviations = residual_draws(x, values, trend, degree, bootstrap, rng)
    none = np.zeros(values.shape[1])
    for _ in range(draws):
        drawn = np.vander(x, degree + 1) @ trend.coef + deviations(len(x))
        experiment = trend.predict(truth) + deviations(1)[0]
        t, g, _, variance, _ = gls(x, drawn, experiment, none, degree)
        null["z_gls"].append((g - truth) / np.sqrt(variance))
        for i, r in held_out_ratios(x, seeds, drawn, degree, t).items():
            null["held_out_design" if design[i] else "held_out_refined"].append(r)
    return summary, row, null


def main_calibration(folders, without, draws, bootstrap):
    print("folder,true_mu_s,z_gls,z_interval,held_out_design_rms,held_out_refined_rms"
          + (",null_z_gls_rms,null_design_rms,null_refined_rms" if draws else ""))
    rng = np.random.default_rng(1)
    pooled = {k: [] for k in ("z_gls", "z_interval", "held_out_design", "held_out_refined",
                              "null_z_gls", "null_held_out_design", "null_held_out_refined")}
    for folder in folders:
        s, row, null = calibration(folder, without, draws, bootstrap, rng)
        line = (f"{folder},{s['mu_s_true']},{row['z_gls']:+.2f},{row['z_interval']:+.2f},"
                f"{rms(row['held_out_design']):.2f},{rms(row['held_out_refined']):.2f}")
        if draws:
            line += "," + ",".join(f"{rms(null[k]):.2f}" for k in null)
        print(line)
        for k in ("z_gls", "z_interval"):
            pooled[k].append(row[k])
        for k in ("held_out_design", "held_out_refined"):
            pooled[k] += row[k]
        for k, v in null.items():
            pooled["null_" + k] += v
    print("# RMS over the folders: " + ", ".join(f"{k} {rms(v):.2f} ({len(v)})"
                                                 for k, v in pooled.items() if v))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+")
    parser.add_argument("--without", default="", help="observables left out, comma list")
    parser.add_argument("--calibration", action="store_true",
                        help="the errors in units of the GLS's and the interval's sigma, and "
                             "the held-out runs' (pseudo-experiments: mu_s_true in summary)")
    parser.add_argument("--null", type=int, default=0, metavar="DRAWS",
                        help="with --calibration: as many Gaussian-null draws per folder")
    parser.add_argument("--bootstrap", action="store_true",
                        help="with --null: the runs' own residuals resampled, not Gaussian")
    a = parser.parse_args()
    without = [n for n in a.without.split(",") if n]
    if a.calibration:
        return main_calibration(a.folders, without, a.null, a.bootstrap)
    print("folder,true_mu_s,calibrate_mu_s,calibrate_low,calibrate_high,mu_s,low,high,width,"
          "chi2,cross_validated_sigma")
    for folder in a.folders:
        s, f = refit(folder, without)
        low, high = s["mu_s_ci95"]
        print(f"{folder},{s.get('mu_s_true', float('nan'))},{s['mu_s']:.4f},{low:.4f},{high:.4f},"
              f"{f['mu_s']:.4f},{f['low']:.4f},{f['high']:.4f},{f['high'] - f['low']:.4f},"
              f"{f['chi2']:.2f},{f['cross_validated']:.4f}")


if __name__ == "__main__":
    main()
