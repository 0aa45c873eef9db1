#!/usr/bin/env python3
"""What the packing's height at the frame before the window holds beside the window's mean
(docs/CALIBRATION.md, "The packing's height before the window"), from calibrate's outputs of
a twin placed before that frame: each one's resolution in ln mu_s at the fit (summary.json's
log_mu_s_resolution: one packing's scatter, with the trend's leverage, over its slope), the
correlation of the twin's packings about their trends (a cubic in ln mu_s through
steady_state_runs.csv), and the scatter of each about it.

  scripts/height_before_window.py FIT_DIR ...

prints one CSV line per folder.
"""
import csv
import json
import sys

import numpy as np

WINDOW, BEFORE = "height_packing_fraction", "height_packing_fraction_before_window"


def main():
    print("folder,true_mu_s,mu_s,window_resolution,before_resolution,window_scatter,"
          "before_scatter,correlation")
    for folder in sys.argv[1:]:
        s = json.load(open(f"{folder}/summary.json"))
        o = s["observables"]
        rows = list(csv.DictReader(l for l in open(f"{folder}/steady_state_runs.csv")
                                   if not l.startswith("#")))
        x = np.log([float(r["mu_s"]) for r in rows])
        design = np.vander(x, 4)
        residual = []
        for name in (WINDOW, BEFORE):
            y = np.array([float(r[name]) for r in rows])
            coef, *_ = np.linalg.lstsq(design, y, rcond=None)
            residual.append(y - design @ coef)
        c = np.corrcoef(residual)[0, 1]
        print(f"{folder},{s.get('mu_s_true', float('nan'))},{s['mu_s']:.4f},"
              f"{o[WINDOW]['log_mu_s_resolution']:.4f},{o[BEFORE]['log_mu_s_resolution']:.4f},"
              f"{o[WINDOW]['packing_scatter']:.3g},{o[BEFORE]['packing_scatter']:.3g},{c:.2f}")


if __name__ == "__main__":
    main()
