#!/usr/bin/env python3
"""How honest the fits' 95 % intervals are over a set of cases: each fit's error in ln mu_s
in units of its interval's standard deviation, z = ln(mu_s / true) / (ln(high / low) / 3.92)
(calibrate's interval is symmetric in ln mu_s), then their mean, their RMS (1 for intervals
of the stated width, less for too wide ones), how many hold the truth, and the chance that
at least that many of so many honest 95 % intervals miss.

Usage: scripts/interval_coverage.py CSV[:COLUMN=VALUE[,COLUMN=VALUE]] ...
Each CSV (comment lines start with #) has columns true_mu_s, mu_s, ci95_low, ci95_high
(or a prefix's: both_sides_mu_s, ... with --prefix); COLUMN=VALUE keeps its matching rows
(every one given)."""
import argparse
import csv
import math


def rows(spec, prefix):
    path, _, keep = spec.partition(":")
    wanted = [k.partition("=")[::2] for k in keep.split(",") if k]
    with open(path) as f:
        for r in csv.DictReader(line for line in f if not line.startswith("#")):
            if any(r.get(column) != value for column, value in wanted):
                continue
            try:
                yield (r.get("case") or r.get("seed") or "", float(r["true_mu_s"]),
                       float(r[prefix + "mu_s"]), float(r[prefix + "ci95_low"]),
                       float(r[prefix + "ci95_high"]))
            except (KeyError, ValueError):
                continue


def misses_at_least(k, n, rate=0.05):
    return sum(math.comb(n, j) * rate**j * (1 - rate)**(n - j) for j in range(k, n + 1))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("csv", nargs="+")
    p.add_argument("--prefix", default="", help="column prefix, e.g. both_sides_")
    a = p.parse_args()
    zs = []
    print("case,true_mu_s,mu_s,ci95_low,ci95_high,z")
    for spec in a.csv:
        for case, true, mu, lo, hi in rows(spec, a.prefix):
            z = math.log(mu / true) / (math.log(hi / lo) / 3.92)
            zs.append(z)
            print(f"{case},{true},{mu},{lo},{hi},{z:+.2f}")
    n = len(zs)
    if n == 0:
        raise SystemExit("interval_coverage.py: no rows with true_mu_s, mu_s and an interval")
    misses = sum(abs(z) > 1.96 for z in zs)
    print(f"# {n} fits: mean z {sum(zs) / n:+.2f}, RMS z {math.sqrt(sum(z * z for z in zs) / n):.2f}, "
          f"{n - misses} hold the truth; at least {misses} misses of {n} honest 95 % intervals: "
          f"chance {misses_at_least(misses, n):.2f}")


if __name__ == "__main__":
    main()
