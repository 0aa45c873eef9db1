#!/usr/bin/env python3
"""How much friction a scan's steady state carries, and whether more observables would add
to it (docs/CALIBRATION.md, issue 17).

Reads a steady-state calibration study's runs (scripts/steady_state_calibration.sh's DIR:
DIR/runs/mu_s_<mu>_seed_<s>.h5, DIR/pseudo_<mu>_seed_<s>.h5, and the window means that
`calibrate` wrote in DIR/fit*/steady_state_runs.csv and DIR/fit*/summary.json), adds
candidate observables measured from the same end-of-cycle frames, and asks of each set of
observables how well one packing pins ln mu_s:

  - resolution: one packing's scatter about the trend over the trend's slope, per
    observable, and for a set the generalized-least-squares combination (Fisher);
  - leave one out: each packing fitted (GLS over ln mu_s against a quadratic trend and the
    residuals' covariance, shrunk to its diagonal as `observable_fit` does) from all the
    others: the rms error in ln mu_s, out of sample;
  - the 12-run twin: each pseudo-experiment fitted from the 3 x 3 design's runs (seeds 1-3
    at --design) and the three packings of new seeds nearest its friction, as
    `calibrate --refine 3` places them.

  scripts/observable_information.py out/early3k --window 3:8 \
      --out docs/data/friction/observable_information_3000.csv

Where the runs have them, the lid's packing fraction and the wall force at full compression
(the apparatus' observables, not a scan's) are fitted with the current four as well, and,
where the study's fits measured it, the wall force at each cycle's end (unloaded).

Candidates (end-of-cycle frames of the window, grains > 1 d from the packing's extent for
the structure; translations as `granmem analyze` measures them, drift removed):
mean_dr (translations, d), rattler_fraction (grains with fewer than 4 neighbours within
1.02 d), high_coordination_fraction (7 or more), fabric_z (the contact normals' zz
component less the mean of xx and yy), first_peak (pairs within 1.01 d over pairs
1.05-1.10 d), compaction (the relative fall of the packing's height across the window)
and rotation_change (the per-cycle rotation's change across it): how fast the packing
still settles.
"""
import argparse
import glob
import json
import os
import re
import sys

import numpy as np
import pandas as pd
from scipy.optimize import minimize_scalar
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "build", "python"))
import granmem  # noqa: E402

CURRENT = ["rot_disp", "bulk_packing_fraction", "coordination", "height_packing_fraction"]
CANDIDATES = ["mean_dr", "rattler_fraction", "high_coordination_fraction", "fabric_z",
              "first_peak", "compaction", "rotation_change"]
GAP = 1.02  # neighbours within this many diameters touch, as `coordination`'s 2 % gap


def run_label(path):
    m = re.search(r"(mu_s|pseudo)_([0-9.]+)_seed_(\d+)\.h5$", path)
    return None if m is None else (m.group(1), round(float(m.group(2)), 4), int(m.group(3)))


def structure_of_frame(p, d):
    """Candidate structure observables of one frame's positions (grains of diameter d)."""
    lo, hi = p.min(0), p.max(0)
    inner = np.all((p > lo + d) & (p < hi - d), axis=1)
    tree = cKDTree(p)
    pairs = tree.query_pairs(d * GAP, output_type="ndarray")
    pairs = pairs[inner[pairs[:, 0]] | inner[pairs[:, 1]]]
    n = p[pairs[:, 1]] - p[pairs[:, 0]]
    n /= np.linalg.norm(n, axis=1)[:, None]
    fabric = n.T @ n / len(n)
    z = np.bincount(pairs.ravel(), minlength=len(p))[inner]
    near = tree.query_pairs(d * 1.10, output_type="ndarray")
    near = near[inner[near[:, 0]] & inner[near[:, 1]]]
    r = np.linalg.norm(p[near[:, 1]] - p[near[:, 0]], axis=1) / d
    return {"rattler_fraction": np.mean(z < 4), "high_coordination_fraction": np.mean(z >= 7),
            "fabric_z": fabric[2, 2] - 0.5 * (fabric[0, 0] + fabric[1, 1]),
            "first_peak": np.mean(r < 1.01) / np.mean(r > 1.05)}


def change_across(cycles, values, window):
    """The least-squares change of `values` across the window."""
    return np.polyfit(cycles, values, 1)[0] * (window[1] - window[0])


def candidates_of_run(path, window):
    run = granmem.read_run(path)
    radius = run["radius"]
    d = 2 * np.median(radius)
    steps = list(run["step"])
    cycles = list(range(window[0], window[1] + 1))
    per_frame = granmem.analyze(path, subtract_drift=True)["per_frame"]
    in_window = per_frame[(per_frame["frame"] >= window[0]) & (per_frame["frame"] <= window[1])]
    values = {"mean_dr": in_window["mean_dr"].mean() / d,
              "rotation_change": change_across(in_window["frame"], in_window["mean_rot_disp"] / d,
                                               window)}
    rows = [structure_of_frame(run["position"][steps.index(c)], d) for c in cycles]
    values.update(pd.DataFrame(rows).mean().to_dict())
    # The packing's height: its grains' extent, bottom to top (the box's section cancels).
    height = [np.ptp(np.concatenate([z + radius, z - radius]))
              for z in (run["position"][steps.index(c)][:, 2] for c in cycles)]
    values["compaction"] = -change_across(cycles, np.log(height), window)
    return values


def current_observables(study):
    """The window means `calibrate` measured: the twin's runs and each experiment."""
    runs = [pd.read_csv(f, comment="#") for f in glob.glob(study + "/fit*/steady_state_runs.csv")]
    table = pd.concat(runs).drop_duplicates(["mu_s", "seed"]).assign(kind="mu_s")
    experiments = []
    for f in glob.glob(study + "/fit*/summary.json"):
        s = json.load(open(f))
        label = run_label(s["experiment"])
        if label is None or s.get("mu_s_true") is None:
            continue
        row = {"kind": "pseudo", "mu_s": label[1], "seed": label[2]}
        row.update({k: v["experiment"] for k, v in s["observables"].items()})
        experiments.append(row)
    table = pd.concat([table, pd.DataFrame(experiments).drop_duplicates(["mu_s", "seed"])])
    table["mu_s"] = table["mu_s"].round(4)
    return table


def quadratic_trend(runs, names):
    """Each observable's quadratic in ln mu_s through the runs: coefficients (3 x m), the
    runs' residuals about it, and the log frictions."""
    x = np.log(runs["mu_s"].to_numpy())
    X = np.vstack([np.ones_like(x), x, x * x]).T
    Y = runs[names].to_numpy()
    B, *_ = np.linalg.lstsq(X, Y, rcond=None)
    return B, Y - X @ B, x


def gls_fit(runs, experiment, names):
    """ln mu_s of `experiment` from `runs`: GLS against each observable's quadratic in ln
    mu_s, covariance of the residuals shrunk to its diagonal by m / (m + spare runs)."""
    B, R, x = quadratic_trend(runs, names)
    spare, m = len(runs) - 3, len(names)
    C = R.T @ R / spare
    shrink = m / (m + spare)
    Ci = np.linalg.inv((1 - shrink) * C + shrink * np.diag(np.diag(C)))
    y = experiment[names].to_numpy(dtype=float)

    def cost(lnmu):
        r = y - np.array([1, lnmu, lnmu * lnmu]) @ B
        return r @ Ci @ r

    return minimize_scalar(cost, bounds=(x.min(), x.max()), method="bounded").x


def resolution(table, names, mu):
    """One packing's error in ln mu_s at mu from `names` (Fisher, all runs' covariance)."""
    B, R, _ = quadratic_trend(table, names)
    C = np.atleast_2d(np.cov(R.T, ddof=3))
    slope = B[1] + 2 * B[2] * np.log(mu)
    return 1 / np.sqrt(slope @ np.linalg.solve(C, slope))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("study")
    ap.add_argument("--window", default="3:8")
    ap.add_argument("--design", default="0.05,0.14,0.4")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    window = tuple(int(v) for v in a.window.split(":"))
    paths = [p for p in glob.glob(a.study + "/runs/mu_s_*_seed_*.h5") +
             glob.glob(a.study + "/pseudo_*_seed_*.h5") if run_label(p)]
    rows = []
    for p in sorted(paths):
        kind, mu, seed = run_label(p)
        rows.append({"kind": kind, "mu_s": mu, "seed": seed, **candidates_of_run(p, window)})
        print(f"measured {os.path.basename(p)}", file=sys.stderr)
    table = pd.DataFrame(rows).merge(current_observables(a.study), on=["kind", "mu_s", "seed"])
    design = [round(float(v), 4) for v in a.design.split(",")]

    sets = {name: [name] for name in CURRENT + CANDIDATES}
    sets["current"] = CURRENT
    sets.update({f"current + {c}": CURRENT + [c] for c in CANDIDATES})
    sets["current + mean_dr + rattler_fraction"] = CURRENT + ["mean_dr", "rattler_fraction"]
    sets["current + all candidates"] = CURRENT + CANDIDATES
    apparatus = [n for n in ("packing_fraction", "wall_force_full_compression") if n in table]
    if apparatus and table[apparatus].notna().all().all():
        sets.update({name: [name] for name in apparatus})
        sets["current + lid height and wall force"] = CURRENT + apparatus
        # The wall's force at each cycle's end (the wall back at its start), where the fits
        # measured it (calibrate since 2026-11-26).
        if "wall_force_unloaded" in table and table["wall_force_unloaded"].notna().all():
            sets["wall_force_unloaded"] = ["wall_force_unloaded"]
            sets["current + wall force unloaded"] = CURRENT + ["wall_force_unloaded"]
            sets["current + lid height and both wall forces"] = (
                CURRENT + apparatus + ["wall_force_unloaded"])
    twin = table[table["kind"] == "mu_s"]
    grid = twin[twin["seed"].isin([1, 2, 3]) & twin["mu_s"].isin(design)]
    added = twin[~twin["seed"].isin([1, 2, 3])]
    pseudo = table[table["kind"] == "pseudo"]
    out = []
    for name, names in sets.items():
        loo = [gls_fit(table.drop(index=table.index[i]), table.iloc[i], names) -
               np.log(table["mu_s"].iloc[i]) for i in range(len(table))]
        errors = []  # none where the study has no packings beyond the design's seeds 1-3
        for _, e in pseudo.iterrows() if len(added) else ():
            near = added["mu_s"].iloc[np.argmin(abs(np.log(added["mu_s"]) - np.log(e["mu_s"])))]
            runs = pd.concat([grid, added[added["mu_s"] == near]])
            errors.append(np.exp(gls_fit(runs, e, names)) - e["mu_s"])
        errors = np.array(errors if errors else [np.nan])
        row = {"observables": name, "packings": len(table),
               "loo_rms_ln_mu_s": np.sqrt(np.mean(np.square(loo))),
               "twin12_rms_error": np.sqrt(np.mean(errors ** 2)),
               "twin12_max_abs_error": np.max(abs(errors)),
               "twin12_within_0.02": int(np.sum(abs(errors) <= 0.02)),
               "twin12_experiments": int(np.sum(np.isfinite(errors)))}
        row.update({f"resolution_ln_mu_s_at_{mu}": resolution(table, names, mu)
                    for mu in (0.1, 0.2, 0.35)})
        out.append(row)
    result = pd.DataFrame(out)
    tmp = a.out + ".tmp"
    with open(tmp, "w") as f:
        f.write(f"# {a.study}: {len(table)} packings of known mu_s, window {a.window}; "
                "scripts/observable_information.py\n")
        result.to_csv(f, index=False, float_format="%.4g")
    os.replace(tmp, a.out)
    pd.set_option("display.width", 250)
    print(result.to_string(index=False, float_format=lambda v: f"{v:.4g}"))


if __name__ == "__main__":
    main()
