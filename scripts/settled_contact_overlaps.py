#!/usr/bin/env python3
"""How the contacts of packings carry the load, from their centres alone: for each run, at each
CYCLE, the touching pairs (centres closer than a diameter) of grains 2 d inside the packing,
their overlaps' mean (um; the normal force is k_n times it), its coefficient of variation, the
share of weak contacts (under 0.3 of the mean) and the 99th percentile over the mean; averaged
over the runs of each group (docs/CALIBRATION.md, "The contact history a placed twin loses,
and what placing from the scans does").
Usage: scripts/settled_contact_overlaps.py CYCLE,CYCLE,... NAME=GLOB [NAME=GLOB ...]"""
import glob
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from twin_runs_motion import frames, inside, touching_pairs  # noqa: E402


def overlap_stats(p, d):
    p, pairs = touching_pairs(p, d)
    bulk = inside(p, 2 * d)
    pairs = pairs[bulk[pairs[:, 0]] & bulk[pairs[:, 1]]]
    overlap = (d - np.linalg.norm(p[pairs[:, 0]] - p[pairs[:, 1]], axis=1)) * 1e6
    m = overlap.mean()
    return [m, overlap.std() / m, (overlap < 0.3 * m).mean(), np.percentile(overlap, 99) / m]


cycles = [int(c) for c in sys.argv[1].split(",")]
print("group,runs,cycle,mean_overlap_um,cv,weak_share,p99_over_mean")
for arg in sys.argv[2:]:
    name, pattern = arg.split("=", 1)
    paths = sorted(glob.glob(pattern))
    per_run = []
    for path in paths:
        pos, step, d = frames(path)
        per_run.append([overlap_stats(pos[step.index(c)], d) for c in cycles])
    mean = np.mean(per_run, axis=0)
    for c, (m, cv, weak, p99) in zip(cycles, mean):
        print(f"{name},{len(paths)},{c},{m:.3f},{cv:.3f},{weak:.3f},{p99:.2f}")
