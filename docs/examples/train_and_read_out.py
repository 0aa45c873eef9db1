"""Simulate -> train -> read the memory out, from Python.

A small packing (400 grains of 5 mm in a 3 cm box under the paper's lid pressure) is
trained by cycles of A = 2 % of the box; its state before training and after 10 cycles is
read out with one cycle at each amplitude A' of a sweep, and the read-out curves (mean
displacement from the state vs A') are drawn, as the paper's Fig. 5. A reduced-scale
demonstration of the workflow (docs/MEMORY.md has the measured study). Run from the
repository root:

    PYTHONPATH=build/python python3 docs/examples/train_and_read_out.py [out_folder]
"""
import pathlib
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.ticker

import granmem

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out/examples")
out.mkdir(parents=True, exist_ok=True)


def show(report):
    if "cycle" in report:
        print(f"  cycle {report['cycle']}/{report['cycles']}, "
              f"{report['particle_steps_per_second']:.2e} particle-steps/s")
    else:
        print(" ", report["line"])


# 1. Deposit and train; keep the state before the first cycle and after the tenth.
train = granmem.simulate(out=out / "train.h5", grains=400, box="3cm", amplitude="2%",
                         cycles=10, keep_states=[0, 10], seed=4, progress=show)
print(train["report"])

# 2. Read both states out, two runs at a time (finished runs are reused if run again).
states = [out / "train_state_cycle0.h5", out / "train_state_cycle10.h5"]
result = granmem.readout(states, out / "readout", amplitudes=[0.5, 1, 3, 4], parallel=2,
                         progress=show)
points = result["points"]
print(points[["state", "trained_cycles", "amplitude_pct", "dr_d", "dr_err_d"]])

# 3. The read-out curves.
fig, ax = plt.subplots(figsize=(5, 3.6))
for (state, cycles), curve in points.groupby(["state", "trained_cycles"]):
    ax.errorbar(curve.amplitude_pct, curve.dr_d, yerr=curve.dr_err_d, marker="o", capsize=2,
                label=f"{cycles} training cycles")
ax.axvline(2, color="0.6", ls="--", lw=1, label="training amplitude")
ax.set(xscale="log", yscale="log", xlabel="read-out amplitude A' [% of the box]",
       ylabel="mean displacement after one cycle [d]",
       title="Memory read-out (400 grains, reduced scale)")
ax.set_xticks([0.5, 1, 2, 3, 4])
ax.xaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
ax.legend(frameon=False)
fig.tight_layout()
fig.savefig(out / "train_and_read_out.png", dpi=120)
print(f"wrote {out / 'train_and_read_out.png'}")
