"""granmem export read by independent readers of the formats: ASE's extended-XYZ reader
(the format's reference implementation, as OVITO maps the same names)."""
import ase.io
import numpy as np

import granmem

from test_simulate import TINY


def test_extended_xyz_is_read_by_ase(tmp_path, cli):
    granmem.simulate(out=tmp_path / "run.h5", cycles=2, **TINY)
    cli("export", "run.h5", "--out", "run.extxyz")
    run = granmem.read_run(tmp_path / "run.h5")
    frames = ase.io.read(tmp_path / "run.extxyz", index=":")
    assert len(frames) == len(run["step"]) == 3
    for t, atoms in enumerate(frames):
        np.testing.assert_array_equal(atoms.arrays["id"], run["id"])
        np.testing.assert_allclose(atoms.positions, run["position"][t], rtol=1e-15)
        np.testing.assert_allclose(atoms.arrays["radius"], run["radius"], rtol=1e-15)
        # OVITO's Orientation order (x, y, z, w); the store's is (w, x, y, z).
        np.testing.assert_allclose(atoms.arrays["orientation"],
                                   run["orientation"][t][:, [1, 2, 3, 0]], rtol=1e-15)
        np.testing.assert_allclose(atoms.cell.lengths(), run["box"][1], rtol=1e-15)
        assert atoms.info["Step"] == run["step"][t] and atoms.info["Units"] == "m"
