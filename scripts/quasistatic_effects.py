#!/usr/bin/env python3
"""What each drive does to a packing's steady state, against what two packings differ by:
the verdict table of docs/QUASISTATIC.md, from scripts/quasistatic_report.sh's
steady_state.csv.

    scripts/quasistatic_effects.py [STEADY_STATE_CSV] [--out drive_effects.csv]

For every friction and drive, over the packings (seeds) run at both it and the slowest
drive: the mean and RMS of the change from the slowest drive of the same packing (mean dr,
mean rotation, packing fraction, wall force), and as the yardstick the RMS difference of
two packings driven alike (seed pairs 1-2, 3-4, ... at this drive and every slower one).
Two tests per quantity: whether the drive shifts it (paired t-test of the mean change:
same-signed changes in every packing), and whether it moves it more than two packings
differ (the ratio of the mean squares of the changes and of the seed pairs' differences,
F(packings, pairs); the pairs re-measure the same packings at several drives, so their
count overstates the yardstick's degrees of freedom). A drive agrees with the slowest where
no test, over its quantities and frictions, has a p-value below --level divided by the
number of tests (Bonferroni). The KS distances against the slowest (median and largest)
are set beside the seed pairs'.
"""
import argparse
import math
import os
import sys

import pandas as pd
from scipy.stats import f as f_distribution
from scipy.stats import ttest_1samp

QUANTITIES = [("mean_dr_d", "dr"), ("mean_rot_disp_d", "rot"),
              ("packing_fraction", "phi"), ("wall_force_full_compression_N", "force")]


def seed_pair_rms(rows, column):
    """RMS difference of seed pairs (1-2, 3-4, ...) run at the same drive."""
    diffs = []
    for (_, drive), g in rows.groupby(["mu_s", "inertial_number"]):
        by_seed = g.set_index("seed")[column]
        diffs += [by_seed[s] - by_seed[s + 1] for s in by_seed.index
                  if s % 2 == 1 and s + 1 in by_seed.index]
    return math.sqrt(sum(d * d for d in diffs) / len(diffs)) if diffs else math.nan, len(diffs)


def drive_effects(table, level):
    out = []
    tests = 2 * len(QUANTITIES) * table["mu_s"].nunique()
    for mu, rows in table.groupby("mu_s"):
        slowest = rows["inertial_number"].min()
        base = rows[rows["inertial_number"] == slowest].set_index("seed")
        for drive, g in rows.groupby("inertial_number"):
            if drive == slowest:
                continue
            no_faster = rows[rows["inertial_number"] <= drive]
            yard = {c: seed_pair_rms(no_faster, c) for c, _ in QUANTITIES}
            ks_pairs = no_faster[["ks_dr_seed1_vs_seed2", "ks_rot_seed1_vs_seed2"]].dropna()
            g = g.set_index("seed")
            seeds = [s for s in g.index if s in base.index]
            row = {"mu_s": mu, "inertial_number": drive, "packings": len(seeds)}
            agrees = True
            for column, short in QUANTITIES:
                change = [g.at[s, column] - base.at[s, column] for s in seeds]
                rms = math.sqrt(sum(c * c for c in change) / len(change))
                row[f"{short}_mean_change"] = sum(change) / len(change)
                row[f"{short}_rms_change"] = rms
                row[f"{short}_seed_pair_rms"] = yard[column][0]
                p = f_distribution.sf((rms / yard[column][0])**2, len(change), yard[column][1])
                shift = ttest_1samp(change, 0).pvalue if len(change) > 1 else math.nan
                row[f"{short}_p"] = p
                row[f"{short}_shift_p"] = shift
                agrees &= p >= level / tests and not shift < level / tests
            for short in ("dr", "rot"):
                ks = g.loc[seeds, f"ks_{short}_vs_slowest"]
                row[f"ks_{short}_median"] = ks.median()
                row[f"ks_{short}_max"] = ks.max()
                row[f"ks_{short}_seed_pairs_median"] = ks_pairs[f"ks_{short}_seed1_vs_seed2"].median()
            row["seed_pairs"] = yard[QUANTITIES[0][0]][1]
            row["tests"] = tests
            row["within_seed_pairs"] = agrees
            out.append(row)
    return pd.DataFrame(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("steady", nargs="?", default="docs/data/quasistatic/steady_state.csv")
    ap.add_argument("--out", default="docs/data/quasistatic/drive_effects.csv")
    ap.add_argument("--level", type=float, default=0.05,
                    help="family p-value: a drive's tests are each held to LEVEL / their number")
    a = ap.parse_args()
    try:
        table = pd.read_csv(a.steady, comment="#")
    except (OSError, pd.errors.ParserError) as e:
        sys.exit(f"quasistatic_effects.py: {a.steady}: {e}")
    effects = drive_effects(table, a.level)
    with open(a.out + ".tmp", "w") as f:
        f.write("# change of each drive's steady state from the slowest drive's, same packing, "
                "against the RMS difference of two packings driven alike (seed pairs); "
                "scripts/quasistatic_effects.py\n")
        effects.to_csv(f, index=False, float_format="%.4g")
    os.replace(a.out + ".tmp", a.out)
    cols = ["mu_s", "inertial_number", "packings"] + [
        f"{s}_{k}" for _, s in QUANTITIES for k in ("mean_change", "seed_pair_rms", "p", "shift_p")] + [
        "ks_dr_median", "ks_rot_median", "within_seed_pairs"]
    print(effects[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"))


if __name__ == "__main__":
    main()
