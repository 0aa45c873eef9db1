#!/usr/bin/env python3
"""What a twin placed from the scans' frame of CYCLE starts from, against a normal draw of the
same size: the scans' errors there (each grain's tracked centre less its true one, their mean
removed) per axis, RMS, excess kurtosis and share beyond 3 sigma; for the touching pairs of
the truth (centres within 1.005 d), how the two grains' errors along the contact correlate,
and the contact lengths' error, RMS and share beyond 15 um, with the share of pairs the
frame makes overlap or open by more than 10 um, each beside an independent normal draw of the
same per-axis RMS (seed 0) (docs/CALIBRATION.md, "The contact history a placed twin loses,
and what placing from the scans does").
Usage: PYTHONPATH=build/python scripts/scan_errors_at_contacts.py CYCLE CASE_DIR ...
(CASE_DIR as scripts/blind_scans.sh leaves it: pseudo.h5, tracks.h5)"""
import os
import sys

import numpy as np
from scipy.stats import kurtosis

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from frame_with_scan_errors import scan_errors  # noqa: E402
from twin_runs_motion import frames, touching_pairs  # noqa: E402

cycle = int(sys.argv[1])
for case in sys.argv[2:]:
    pos, step, d = frames(f"{case}/pseudo.h5")
    truth = pos[step.index(cycle)]
    err, has = scan_errors(f"{case}/tracks.h5", truth, cycle, d)
    e = (err - err[has].mean(0)) * 1e6
    rms = e[has].std(0)
    normal = np.random.default_rng(0).normal(size=e.shape) * rms
    _, pairs = touching_pairs(truth, 1.005 * d)
    pairs = pairs[has[pairs[:, 0]] & has[pairs[:, 1]]]
    u = truth[pairs[:, 1]] - truth[pairs[:, 0]]
    gap = np.linalg.norm(u, axis=1)
    u /= gap[:, None]
    overlap = (d - gap) * 1e6
    along = [(e[pairs[:, k]] * u).sum(1) for k in (0, 1)]
    lengths = {"scans": along[1] - along[0],
               "normal": ((normal[pairs[:, 1]] - normal[pairs[:, 0]]) * u).sum(1)}
    name = os.path.basename(case.rstrip("/"))
    print(f"{name}: errors RMS x, y, z {rms.round(2)} um, excess kurtosis "
          f"{kurtosis(e[has], axis=0).round(2)}, beyond 3 sigma "
          f"{(100 * (np.abs(e[has]) > 3 * rms).mean(0)).round(2)} %")
    print(f"  {len(pairs)} contacts: the two errors along the contact correlate "
          f"{np.corrcoef(along[0], along[1])[0, 1]:+.3f}")
    for k, dl in lengths.items():
        print(f"  {k:6s}: contact length error RMS {dl.std():.2f} um, beyond 15 um "
              f"{100 * (np.abs(dl) > 15).mean():.2f} %, overlapping > 10 um "
              f"{100 * (overlap - dl > 10).mean():.2f} %, open > 10 um "
              f"{100 * (overlap - dl < -10).mean():.2f} %")
