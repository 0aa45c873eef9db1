#!/usr/bin/env python3
"""The placement probe's effect against one packing's scatter: for each fit folder's
summary.json, each fitted observable's |probe less its source run| over the twin's packing
scatter there, then their mean and RMS over all (two independent realizations of a packing
differ by sqrt(2) scatters RMS: a probe reading that measures chaos, not the placement).

Usage: scripts/probe_against_scatter.py FIT_DIR ..."""
import json
import math
import sys
from pathlib import Path


def ratios(fit_dir):
    s = json.loads((Path(fit_dir) / "summary.json").read_text())
    probe = s.get("placement_probe")
    if not probe:
        return []
    fitted = s["observables"]
    return [abs(effect) / fitted[name]["packing_scatter"]
            for name, effect in probe["less_source"].items()
            if fitted.get(name, {}).get("packing_scatter")]


def main():
    if len(sys.argv) < 2:
        raise SystemExit(__doc__.splitlines()[-1])
    every = []
    for fit_dir in sys.argv[1:]:
        r = ratios(fit_dir)
        every += r
        print(fit_dir, " ".join(f"{x:.2f}" for x in r))
    if not every:
        raise SystemExit("probe_against_scatter.py: no fit with a placement probe")
    n = len(every)
    print(f"# {n} observables: mean {sum(every) / n:.2f}, RMS {math.sqrt(sum(x * x for x in every) / n):.2f}"
          f" scatters (independent realizations: RMS {math.sqrt(2):.2f})")


if __name__ == "__main__":
    main()
