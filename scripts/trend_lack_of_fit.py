#!/usr/bin/env python3
"""Does a calibrate fit's trend need the cubic? For each observable of a fit folder's
steady_state_runs.csv, the F test of a cubic's extra term in ln mu_s against the runs'
residuals about it (docs/CALIBRATION.md, "The scans' floor at their bottom layer, the cubic,
and the placement probe"): F and its p value, small p where the quadratic leaves a trend the
runs' scatter does not explain.
Usage: scripts/trend_lack_of_fit.py FIT_DIR ..."""
import json
import sys

import numpy as np
import pandas as pd
from scipy import stats

for folder in sys.argv[1:]:
    runs = pd.read_csv(f"{folder}/steady_state_runs.csv", comment="#")
    summary = json.load(open(f"{folder}/summary.json"))
    x = np.log(runs.mu_s.values)
    tests = []
    for name in runs.columns[2:]:
        y = runs[name].values
        if not np.all(np.isfinite(y)):
            continue
        residual = {d: np.sum((np.polyval(np.polyfit(x, y, d), x) - y) ** 2) for d in (2, 3)}
        spare = len(y) - 4
        f = (residual[2] - residual[3]) / (residual[3] / spare)
        tests.append(f"{name} F {f:.1f} p {1 - stats.f.cdf(f, 1, spare):.3f}")
    print(f"{folder} (mu_s {summary['mu_s']:.4g}): " + "; ".join(tests))
