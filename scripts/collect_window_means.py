#!/usr/bin/env python3
"""The window means behind the steady-state fits of docs/CALIBRATION.md, in one table.

For every fit directory DIR/fit_[refine3_]pseudo_MU_seed_S (made by
scripts/steady_state_calibration.sh) the experiment's values (summary.json) and the twin's
runs (steady_state_runs.csv), on the observables that fit used; an observable a fit did
not use is nan. tests/calibration/observable_fit_test.cpp re-fits every case from it.

    scripts/collect_window_means.py out/early3k out/ss40 out/cov2k \
        --out docs/data/friction/pseudo_experiment_window_means.csv
"""
import argparse
import csv
import json
import math
import pathlib
import re
import sys

OBSERVABLES = ["rot_disp", "bulk_packing_fraction", "coordination",
               "height_packing_fraction", "wall_force_full_compression", "wall_force_unloaded"]


def cases(study):
    for d in sorted(study.glob("fit_*pseudo_*_seed_*")):
        m = re.fullmatch(r"fit_(refine3_)?pseudo_([0-9.]+)_seed_([0-9]+)", d.name)
        if m and (d / "summary.json").is_file() and (d / "steady_state_runs.csv").is_file():
            yield d, bool(m.group(1)), float(m.group(2)), int(m.group(3))


def grains(summary):
    return int(summary["settings"]["grains"])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("studies", nargs="+", type=pathlib.Path)
    parser.add_argument("--out", required=True, type=pathlib.Path)
    args = parser.parse_args()
    rows, comment = [], []
    for study in args.studies:
        for d, refined, truth, seed in cases(study):
            summary = json.loads((d / "summary.json").read_text())
            used = list(summary["observables"])
            unknown = [n for n in used if n not in OBSERVABLES]
            if unknown:
                sys.exit(f"{d}: observable {unknown[0]} is not one this table has")
            case = len(comment)
            lo, hi = summary["mu_s_ci95"]
            comment.append(f"# case {case}: {d} ({grains(summary)} grains, window "
                           f"{summary['window'][0]}:{summary['window'][1]}), fitted "
                           f"{summary['mu_s']:.4f} ({lo:.4f}-{hi:.4f})")
            base = {"case": case, "refined": int(refined), "grains": grains(summary),
                    "mu_s_true": truth}
            experiment = {n: summary["observables"][n]["experiment"] for n in used}
            rows.append({**base, "role": 0, "mu_s": truth, "seed": seed,
                         **{n: experiment.get(n, math.nan) for n in OBSERVABLES}})
            with open(d / "steady_state_runs.csv") as f:
                runs = csv.DictReader(line for line in f if not line.startswith("#"))
                for r in runs:
                    rows.append({**base, "role": 1, "mu_s": float(r["mu_s"]),
                                 "seed": int(r["seed"]),
                                 **{n: float(r[n]) if n in used else math.nan
                                    for n in OBSERVABLES}})
    fields = ["case", "refined", "grains", "role", "mu_s_true", "mu_s", "seed", *OBSERVABLES]
    tmp = args.out.with_suffix(".tmp")
    with open(tmp, "w", newline="") as f:
        f.write("# steady-state window means of the pseudo-experiments (role 0) and their twins'\n"
                "# runs (role 1); rot_disp in grain diameters, wall force in N; nan: not used\n")
        f.writelines(line + "\n" for line in comment)
        writer = csv.DictWriter(f, fieldnames=fields, lineterminator="\n")
        writer.writeheader()
        for r in rows:
            writer.writerow({k: (repr(v) if isinstance(v, float) and not math.isnan(v) else
                                 ("nan" if isinstance(v, float) else v)) for k, v in r.items()})
    tmp.replace(args.out)
    print(f"{len(comment)} cases, {len(rows)} rows -> {args.out}")


if __name__ == "__main__":
    main()
