#!/usr/bin/env python3
"""What a placed twin loses with its contact history: the window means of the end-of-cycle
displacement (scripts/twin_runs_motion.py's) and of the bulk packing fraction (granmem
analyze's, the store's radii) of the truth; of the truth's own state at the frame before the
window continued with its history (CASE/kept1-9.h5, moved by 1 nm; CASE/kicked1-9.h5, by 0.5 um,
a fifth of a contact's overlap; their cycles 1..n); and of the twin placed from that frame
at the truth's friction (CASE/placed/runs) and, where there, from the scans
(CASE/scanplaced/runs). dr in 1e-4 d, the packing fraction less the truth's in 1e-4, and
the touching pairs (centres closer than a diameter) per grain 2 d inside the packing at the
frame it starts from (a placed twin's: placed and settled) and at the window's end
(docs/CALIBRATION.md, "The contact history a placed twin loses").
Usage: PYTHONPATH=build/python scripts/history_kept_or_lost.py CASE_DIR MU_S FIRST:LAST"""
import glob
import os
import sys

import granmem
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from twin_runs_motion import cycle_dr, frames, inside, touching_pairs  # noqa: E402


def bulk_packing_fraction(path, first, last):
    f = granmem.analyze(path)["per_frame"].set_index("frame")["packing_fraction"]
    return f.loc[first:last].to_numpy()


def touching(pos, step, d, cycles):
    out = []
    for c in cycles:
        p, pairs = touching_pairs(pos[step.index(c)], d)
        out.append(np.bincount(pairs.ravel(), minlength=len(p))[inside(p, 2 * d)].mean())
    return out


case, mu = sys.argv[1], sys.argv[2]
first, last = map(int, sys.argv[3].split(":"))
n = last - first + 1
runs = {"truth": [(f"{case}/truth.h5", first)],
        "kept": [(p, 1) for p in sorted(glob.glob(f"{case}/kept[0-9].h5"))],
        "kicked": [(p, 1) for p in sorted(glob.glob(f"{case}/kicked[0-9].h5"))],
        "placed": [(p, first) for p in
                   sorted(glob.glob(f"{case}/placed/runs/mu_s_{mu}_seed_*.h5"))],
        "scan_placed": [(p, first) for p in
                        sorted(glob.glob(f"{case}/scanplaced/runs/mu_s_{mu}_seed_*.h5"))]}
truth_pf = bulk_packing_fraction(f"{case}/truth.h5", first, last).mean()
print("kind,packing,dr_" + ",dr_".join(str(c) for c in range(first, last + 1)) +
      ",dr,bulk_packing_fraction_less_truth,touching_at_start,touching_at_end")
table = {}
for kind, paths in runs.items():
    for k, (path, start) in enumerate(paths):
        pos, step, d = frames(path)
        dr = np.array([cycle_dr(pos, step, d, c) for c in range(start, start + n)]) * 1e4
        pf = (bulk_packing_fraction(path, start, start + n - 1).mean() - truth_pf) * 1e4
        z = touching(pos, step, d, (start - 1, start + n - 1))
        table.setdefault(kind, []).append((dr.mean(), pf, *z))
        print(f"{kind},{k + 1}," + ",".join(f"{x:.2f}" for x in dr) +
              f",{dr.mean():.2f},{pf:+.2f},{z[0]:.3f},{z[1]:.3f}")
for kind, v in table.items():
    v = np.array(v)
    se = v.std(0, ddof=1) / np.sqrt(len(v)) if len(v) > 1 else np.full(4, np.nan)
    print(f"# {kind}, {len(v)} packings: dr {v[:, 0].mean():.2f} +- {se[0]:.2f}, "
          f"bulk packing fraction less the truth's {v[:, 1].mean():+.2f} +- {se[1]:.2f}, "
          f"touching {v[:, 2].mean():.3f} -> {v[:, 3].mean():.3f}")
