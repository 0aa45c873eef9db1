#!/usr/bin/env python3
"""How many grains a placed twin's runs hold against the packing's count, beside the placed
packing's read-back at its frame (docs/CALIBRATION.md, "A broken track placed twice"): a
track the linker broke between the preparation's scan and the window's, taken from a later
frame as if the preparation had missed its grain, is one grain too many.

  scripts/placed_count_read_back.py FIT_DIR ...

FIT_DIR: calibrate's output of a placed twin (summary.json, runs/). Prints per folder the
protocol's grains, the run's grains, and the read-back (placed_frame_less_experiment) of
the height and bulk packing fractions, also in units of one packing's scatter. Needs
build/python on PYTHONPATH.
"""
import glob
import json
import sys

import numpy as np

import granmem


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    print("folder,true_mu_s,grains,placed,height_read_back,height_read_back_scatters,"
          "bulk_read_back,bulk_read_back_scatters")
    for folder in sys.argv[1:]:
        s = json.load(open(f"{folder}/summary.json"))
        run = granmem.read_run(sorted(glob.glob(f"{folder}/runs/*.h5"))[0])
        radius = np.asarray(run["radius"])
        placed = int(np.isclose(radius, np.median(radius)).sum())  # the lid is no grain
        back = s.get("placed_frame_less_experiment", {})
        o = s["observables"]
        cells = []
        for name in ("height_packing_fraction", "bulk_packing_fraction"):
            value = back.get(name, float("nan"))
            cells += [f"{value:+.5f}", f"{value / o[name]['packing_scatter']:+.2f}"]
        print(f"{folder},{s.get('mu_s_true', float('nan'))},{s['settings']['grains']},{placed},"
              + ",".join(cells))


if __name__ == "__main__":
    main()
