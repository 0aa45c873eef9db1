"""Fit the DEM's sliding friction to an experiment, from Python.

A pseudo-experiment (a granmem run at a friction the fit is not told: 200 grains of 5 mm in
a 3 cm box under the paper's lid pressure, A = 2 % of the box, 6 cycles) stands for tracked
scans. Its simulated twin runs at four frictions on two packings each; the friction is
fitted on the steady-state observables (window means of rotation, packing fraction,
coordination, wall force; docs/CALIBRATION.md says which identify friction), and each
observable of the twin is drawn against mu_s with the experiment's value and the fitted
interval. A demonstration of the workflow at toy scale, with a shortened cycle: the
measured calibration study is in docs/CALIBRATION.md. Run from the repository root:

    PYTHONPATH=build/python python3 docs/examples/calibrate_friction.py [out_folder]
"""
import json
import pathlib
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.ticker
import pandas as pd

import granmem

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out/examples")
out.mkdir(parents=True, exist_ok=True)
protocol = dict(grains=200, box="3cm", amplitude="2%", period="0.2s")


def show(report):
    print(" ", report.get("line", ""))


# 1. The "experiment": granmem at mu_s = 0.15, on its own packing (seed 11).
granmem.simulate(out=out / "experiment.h5", cycles=6, mu_s=0.15, seed=11, threads=2,
                 progress=show, **protocol)

# 2. The twin at four frictions x two packings, fitted on cycles 4-6 (finished runs are
# reused when run again).
fit = granmem.calibrate(out / "experiment.h5", out / "calibration", mu_s=[0.05, 0.1, 0.2, 0.4],
                        window=(4, 6), observables="steady-state", fit_only=True, parallel=2,
                        progress=show, **protocol)
print(fit["report"])
lo, hi = fit["mu_s_ci95"]

# 3. Each observable of the twin against mu_s, the experiment's value, the fitted interval.
runs = pd.read_csv(out / "calibration" / "steady_state_runs.csv", comment="#")
summary = json.loads((out / "calibration" / "summary.json").read_text())
names = list(summary["observables"])
fig, axes = plt.subplots(1, len(names), figsize=(3.2 * len(names), 3.2), squeeze=False)
for ax, name in zip(axes[0], names):
    for seed, packing in runs.groupby("seed"):
        ax.plot(packing.mu_s, packing[name], "o-", ms=4, label=f"twin, packing {seed}")
    measured = summary["observables"][name]
    ax.axhspan(measured["experiment"] - measured["packing_scatter"],
               measured["experiment"] + measured["packing_scatter"], color="0.85",
               label="experiment +- one packing's scatter")
    ax.axvspan(lo, hi, color="tab:green", alpha=0.2, label="fitted mu_s, 95 %")
    ax.axvline(fit["true_mu_s"], color="k", ls="--", lw=1, label="true mu_s")
    ax.set(xscale="log", xlabel="sliding friction mu_s", title=name.replace("_", " "))
    ax.set_xticks([0.05, 0.1, 0.2, 0.4])
    ax.xaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
axes[0][0].legend(frameon=False, fontsize=7)
fig.suptitle(f"fitted mu_s = {fit['mu_s']:.3f} (95 % {lo:.3f}-{hi:.3f}), "
             f"true {fit['true_mu_s']:.2f}")
fig.tight_layout()
fig.savefig(out / "calibrate_friction.png", dpi=110)
print(f"wrote {out / 'calibrate_friction.png'}")
