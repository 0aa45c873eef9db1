#!/usr/bin/env python3
"""What the scans themselves read of the packing's structure, against the DEM's exact frames:
the window mean of the bulk packing fraction the fit took from the scans (its summary.json,
the twin's grain radius) less the exact frames' (granmem analyze's), and the packing's bottom
and top (the end layers' means, as the height's packing fraction takes them: the lowest
grains' bottoms and the highest grains' tops, a face's worth of grains each) from the scans,
from the exact frames and from the exact frames moved by the twin's model of the scans' error
(the summary's locating error from the contacts). In 1e-4 and um (docs/CALIBRATION.md,
"The contact history a placed twin loses, and what placing from the scans does").
Usage: PYTHONPATH=build/python scripts/scans_structure_against_truth.py CASE_DIR ...
(CASE_DIR as scripts/blind_scans.sh leaves it: pseudo.h5, tracks.h5, fit/summary.json)"""
import json
import os
import sys

import granmem
import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from twin_runs_motion import frames  # noqa: E402


def end_layers(p, r, face):
    z = p[np.all(np.isfinite(p), axis=1), 2]
    k = max(1, round(face / (16 * r * r)))
    return np.sort(z - r)[:k].mean(), np.sort(z + r)[-k:].mean()


print("case,bulk_packing_fraction_scans_less_exact_1e-4,bottom_scans_less_exact_um,"
      "bottom_model_less_exact_um,top_scans_less_exact_um,top_model_less_exact_um,"
      "height_scans_less_model_um,height_mm")
rng = np.random.default_rng(2026112937)
for case in sys.argv[1:]:
    s = json.load(open(f"{case}/fit/summary.json"))
    first, last = s["window"]
    exact = granmem.analyze(f"{case}/pseudo.h5")["per_frame"].set_index("frame")
    bulk = s["observables"]["bulk_packing_fraction"]["experiment"] - \
        exact["packing_fraction"].loc[first:last].mean()
    err = s["locating_error_from_contacts"]
    sigma = np.array([err["across_um"], err["across_um"], err["along_z_um"]]) * 1e-6
    tp, ts, d = frames(f"{case}/pseudo.h5")
    sp, ss, _ = frames(f"{case}/tracks.h5")
    with h5py.File(f"{case}/pseudo.h5", "r") as f:
        face = np.prod(f["particles/grains/box/edges"][:2])  # metres, as frames() gives
    ends = []
    for c in range(first, last + 1):
        t = tp[ts.index(c)]
        model = t + rng.normal(size=t.shape) * sigma
        ends.append([*end_layers(t, d / 2, face), *end_layers(sp[ss.index(c)], d / 2, face),
                     *end_layers(model, d / 2, face)])
    e = np.mean(ends, 0) * 1e6
    print(f"{os.path.basename(case.rstrip('/'))},{bulk * 1e4:+.2f},{e[2] - e[0]:+.1f},"
          f"{e[4] - e[0]:+.1f},{e[3] - e[1]:+.1f},{e[5] - e[1]:+.1f},"
          f"{(e[3] - e[2]) - (e[5] - e[4]):+.1f},{(e[1] - e[0]) / 1e3:.1f}")
