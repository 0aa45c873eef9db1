"""Synthetic packings with a known truth, shared by the tests."""
import os
import subprocess

import numpy as np
import pandas as pd
import pytest

RADIUS_MM = 2.5
VOXEL_MM = 5.0 / 10  # a grain diameter of 10 voxels


def lattice(seed=1, shift=(0.0, 0.0, 0.0)):
    """18 grains of 5 mm on a jittered 3 x 3 x 2 lattice (spacing 5.6 mm), random axes."""
    rng = np.random.default_rng(seed)
    centres = np.array([(i, j, k) for k in range(2) for j in range(3) for i in range(3)],
                       dtype=float) * 5.6 + 4.0
    centres += rng.uniform(-0.2, 0.2, centres.shape) + np.asarray(shift)
    axes = rng.normal(size=centres.shape)
    axes /= np.linalg.norm(axes, axis=1)[:, None]
    return pd.DataFrame({"particle": np.arange(len(centres)) + 100,
                         "x": centres[:, 0], "y": centres[:, 1], "z": centres[:, 2],
                         "radius": RADIUS_MM, "ax": axes[:, 0], "ay": axes[:, 1], "az": axes[:, 2]})


@pytest.fixture
def cli(tmp_path):
    """Runs the granmem command line in the test's folder; returns its stdout."""
    exe = os.environ.get("GRANMEM_EXE", "granmem")

    def run(*args):
        done = subprocess.run([exe, *map(str, args)], cwd=tmp_path, capture_output=True,
                              text=True)
        assert done.returncode == 0, done.stderr
        return done.stdout
    return run
