"""locate on grains in flat layers and on the sample's random-packing scans (docs/BENCHMARKS.md,
"Layered packings"). Run from the repository root after scripts/build.sh:

    PYTHONPATH=build/python python3 bench/layered_locate.py
"""
import pathlib

import numpy as np
import pandas as pd

import granmem


def nearest_errors(found, truth, voxel):
    f = found[["x", "y", "z"]].to_numpy() / np.asarray(voxel)
    t = truth[["x", "y", "z"]].to_numpy()
    k = np.linalg.norm(f[None] - t[:, None], axis=2).argmin(axis=1)
    return f[k] - t


def layers(count, seed):
    """3 x 3 x count lattice of 5 mm grains on 5.6 mm, jittered 0.2 mm, 10 voxels across."""
    rng = np.random.default_rng(seed)
    c = np.array([(i, j, k) for k in range(count) for j in range(3) for i in range(3)], float)
    c = c * 5.6 + 4 + rng.uniform(-0.2, 0.2, c.shape)
    grains = pd.DataFrame(dict(x=c[:, 0], y=c[:, 1], z=c[:, 2], radius=2.5))
    stack, voxel, truth = granmem.render(grains, length_unit="mm", diameter_px=10, seed=seed)
    for correction in (True, False):
        found = granmem.locate(stack, diameter="5mm", voxel_size=voxel, unit="mm",
                               illumination=correction)
        e = nearest_errors(found, truth, voxel)
        per_layer = [round(e[9 * k:9 * (k + 1), 2].mean(), 3) for k in range(count)]
        print(f"{count} layers (seed {seed}), correction {correction}: {len(found)} found, "
              f"RMS {np.sqrt((e ** 2).sum(axis=1).mean()):.3f} voxel, layers' mean z error "
              f"{per_layer}")


def sample_scans():
    scans = pathlib.Path("sample_data/scans")
    errors = []
    for f in range(3):
        stack, voxel, unit = granmem.read_stack(scans / f"scan{f}.tif")
        found = granmem.locate(stack, diameter="5mm", voxel_size=voxel, unit=unit)
        e = nearest_errors(found, pd.read_csv(scans / f"truth{f}.csv", comment="#"), voxel)
        errors.append(e[np.linalg.norm(e, axis=1) < 1.5])
    e = np.concatenate(errors)
    print(f"sample scans: {len(e)} grains, RMS x / y / z {np.sqrt((e ** 2).mean(axis=0)).round(4)}"
          " voxel")


for count, seed in [(2, 3), (4, 7), (5, 2)]:
    layers(count, seed)
sample_scans()
