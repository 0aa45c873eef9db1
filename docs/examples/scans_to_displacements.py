"""Scans -> grains -> tracks -> the pdf of displacements, from Python.

The sample's three laser-sheet scans (400 grains of 5 mm, one scan after each of the first
three compression cycles) are located, linked and differenced; the located displacements
are compared with the rendered truth. Run from the repository root:

    PYTHONPATH=build/python python3 docs/examples/scans_to_displacements.py [out_folder]
"""
import pathlib
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import granmem

scans = pathlib.Path("sample_data/scans")
out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out/examples")
out.mkdir(parents=True, exist_ok=True)

# 1. Each scan, a numpy array (z, y, x) with its voxel size, located into a DataFrame.
grains = []
for frame in range(3):
    stack, voxel_size, unit = granmem.read_stack(scans / f"scan{frame}.tif")
    found = granmem.locate(stack, diameter="5mm", voxel_size=voxel_size, unit=unit, frame=frame)
    print(f"scan {frame}: {stack.shape} voxels of {voxel_size} {unit}: {len(found)} grains")
    grains.append(found)

# 2. Tracks, trackpy's shape: frame, particle, x, y, z, ...
tracks = granmem.link(grains)
print(f"{tracks.attrs['summary']['tracks']} tracks over {tracks.frame.nunique()} scans")

# 3. Displacements over each cycle, the packing's drift removed.
moved = pd.concat([granmem.motion(tracks, f, f + 1, subtract_drift=True).assign(cycle=f + 1)
                   for f in range(2)])

# The truth: the rendered grains' own displacements (voxel coordinates -> mm), drift removed.
truth = [pd.read_csv(scans / f"truth{f}.csv", comment="#").set_index("particle")
         for f in range(3)]
voxel = np.asarray(grains[0].attrs["voxel_size"])
true_dr = []
for f in range(2):
    d = (truth[f + 1][["x", "y", "z"]] - truth[f][["x", "y", "z"]]).dropna().to_numpy() * voxel
    true_dr.append(np.linalg.norm(d - d.mean(axis=0), axis=1))
true_dr = np.concatenate(true_dr)

# 4. The figure: pdfs of |dr| located and true, in grain diameters (5 mm in the scans' unit).
d = 5.0 * {"m": 1e-3, "cm": 0.1, "mm": 1.0, "um": 1e3}[unit]
bins = np.logspace(-3, 0, 31)
fig, ax = plt.subplots(figsize=(5, 3.6))
ax.hist(true_dr / d, bins=bins, density=True, histtype="step", lw=2, color="0.6",
        label=f"rendered truth ({len(true_dr)})")
ax.hist(moved.dr / d, bins=bins, density=True, histtype="step", lw=1.2, color="C0",
        label=f"located and linked ({len(moved)})")
ax.set(xscale="log", yscale="log", xlabel="displacement over one cycle, |dr| / d",
       ylabel="pdf", title="Scans to displacements (sample scans, cycles 1-2)")
ax.legend(frameon=False, loc="lower left")
fig.tight_layout()
fig.savefig(out / "scans_to_displacements.png", dpi=120)
print(f"median |dr|: located {np.median(moved.dr) / d:.4f} d, true {np.median(true_dr) / d:.4f} d")
print(f"wrote {out / 'scans_to_displacements.png'}")
