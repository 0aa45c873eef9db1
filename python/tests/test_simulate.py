"""granmem.simulate: the command line's run from Python, interrupted and resumed."""
import shutil

import numpy as np
import pandas as pd
import pytest

import granmem

TINY = dict(grains=60, box="2cm", amplitude="1%", period="20ms", seed=3, threads=1)


def test_simulate_in_python_equals_the_command_line(tmp_path, cli):
    reports = []
    summary = granmem.simulate(out=tmp_path / "py.h5", cycles=3, progress=reports.append,
                               **TINY)
    assert summary["cycles_done"] == 3 and summary["grains"] == 60
    assert summary["settings"]["mu-s"] == "0.2"  # the paper's default
    assert [r["cycle"] for r in reports if "cycle" in r] == [1, 2, 3]
    assert any(r.get("line", "").startswith("settled: packing fraction") for r in reports)
    cli("simulate", "--grains", "60", "--box", "2cm", "--amplitude", "1%", "--period", "20ms",
        "--seed", "3", "--threads", "1", "--cycles", "3", "--out", "cli.h5")
    ours, theirs = granmem.read_run(tmp_path / "py.h5"), granmem.read_run(tmp_path / "cli.h5")
    assert ours["position"].shape == (4, 60, 3)  # the packing before the first cycle, then 3
    np.testing.assert_array_equal(ours["position"], theirs["position"])
    np.testing.assert_array_equal(ours["orientation"], theirs["orientation"])


def test_an_interrupted_run_resumes_to_the_same_state(tmp_path):
    whole = granmem.simulate(out=tmp_path / "whole.h5", cycles=60, **TINY)

    def stop_after_cycle_1(report):
        if report.get("cycle") == 1:
            raise KeyboardInterrupt  # as Ctrl-C would, between two cycles' reports

    with pytest.raises(KeyboardInterrupt):
        granmem.simulate(out=tmp_path / "cut.h5", cycles=60, progress=stop_after_cycle_1,
                         **TINY)
    # Stopped within the run (the report reaches Python a moment after the cycle ends).
    assert granmem.read_run(tmp_path / "cut.h5")["position"].shape[0] < 61
    checkpoint = tmp_path / "cut.checkpoint.h5"
    resumed = granmem.simulate(resume=checkpoint, threads=1)
    assert resumed["cycles_done"] == 60
    a, b = granmem.read_run(tmp_path / "whole.h5"), granmem.read_run(tmp_path / "cut.h5")
    np.testing.assert_array_equal(a["position"], b["position"])
    assert whole["checkpoint"].endswith("whole.checkpoint.h5")


def test_bad_settings_are_one_clear_error(tmp_path):
    with pytest.raises(granmem.Error, match="no setting 'friction'"):
        granmem.simulate(out=tmp_path / "x.h5", friction=0.3)
    with pytest.raises(granmem.Error, match="--box"):
        granmem.simulate(out=tmp_path / "x.h5", grains=60, box="-2cm")
    assert not (tmp_path / "x.h5").exists()


def test_ctrl_c_stops_with_a_checkpoint(tmp_path):
    # A real SIGINT, sent once the run reports its first cycle.
    import os
    import signal
    import subprocess
    import sys
    script = (
        "import sys, granmem\n"
        "def report(r):\n"
        "    if r.get('cycle') == 1: print('cycling', flush=True)\n"
        f"granmem.simulate(out={str(tmp_path / 'run.h5')!r}, cycles=100000, grains=60,\n"
        "                 box='2cm', amplitude='1%', period='20ms', threads=1, progress=report)\n")
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=dict(os.environ))
    assert child.stdout.readline() == "cycling\n"
    child.send_signal(signal.SIGINT)
    _, err = child.communicate(timeout=60)
    assert child.returncode != 0 and "KeyboardInterrupt" in err, err
    frames = granmem.read_run(tmp_path / "run.h5")["position"].shape[0]
    assert 2 <= frames < 100001
    resumed = granmem.simulate(resume=tmp_path / "run.checkpoint.h5", cycles=frames + 1,
                               threads=1)
    assert resumed["cycles_done"] == frames + 1


@pytest.mark.skipif(shutil.which("lmp") is None, reason="no lmp (Debian's lammps)")
def test_the_protocol_runs_on_lammps_from_python(tmp_path):
    # The same settings, engine="lammps": granmem's deposit cycled by LAMMPS, read back as
    # a store with cavity axes and no orientations; the lid where the embedded DEM has it.
    small = dict(grains=150, box="2.5cm", cycles=1, threads=1)
    lines = []
    summary = granmem.simulate(out=tmp_path / "lmp.h5", engine="lammps",
                               progress=lambda r: lines.append(r.get("line", "")), **small)
    assert summary["cycles_done"] == 1 and summary["settings"]["engine"] == "lammps"
    assert any(line.startswith("running the cycles on LAMMPS") for line in lines)
    granmem.simulate(out=tmp_path / "dem.h5", **small)
    lmp, dem = granmem.read_run(tmp_path / "lmp.h5"), granmem.read_run(tmp_path / "dem.h5")
    assert lmp["orientation"] is None and lmp["axis"].shape == (2, 150, 3)
    np.testing.assert_allclose(np.linalg.norm(lmp["axis"], axis=2), 1.0, atol=1e-12)
    np.testing.assert_allclose(lmp["position"][0], dem["position"][0], atol=1e-12)
    lid = lmp["observables"]["lid_height"]["value"], dem["observables"]["lid_height"]["value"]
    np.testing.assert_allclose(lid[0], lid[1], rtol=1e-3)


def test_readout_in_python_equals_the_command_line(tmp_path, cli):
    granmem.simulate(out=tmp_path / "train.h5", cycles=2, keep_states=[2], **TINY)
    state = tmp_path / "train_state_cycle2.h5"
    reports = []
    ours = granmem.readout(state, tmp_path / "py", amplitudes=[0.5, 2], parallel=1,
                           bootstrap=20, progress=reports.append)
    points = ours["points"]
    # Two amplitudes and the training amplitude (1 %), one read-out cycle each.
    assert list(points.amplitude_pct) == pytest.approx([0.5, 1, 2])
    assert (points.dr_d > 0).all()
    assert reports[-1]["line"] == "readout: 3/3 runs done"
    cli("readout", "--from", state, "--amplitudes", "0.5%,2%", "--parallel", "1",
        "--bootstrap", "20", "--out", "cli")
    theirs = pd.read_csv(tmp_path / "cli" / "readout.csv", comment="#")
    assert list(theirs.columns) == list(points.columns)
    for c in points.columns:
        np.testing.assert_allclose(points[c], theirs[c], rtol=1e-12, equal_nan=True, err_msg=c)


def test_compare_in_python_equals_the_command_line(tmp_path, cli):
    for mu, name in [(0.1, "a.h5"), (0.5, "b.h5")]:
        granmem.simulate(out=tmp_path / name, cycles=4, mu_s=mu, **TINY)
    ours = granmem.compare(tmp_path / "a.h5", tmp_path / "b.h5", tmp_path / "py",
                           window=(2, 4), label_a="mu 0.1", label_b="mu 0.5")
    assert set(ours["distances"]) == {"dr", "rot_disp"}
    assert 0 < ours["distances"]["dr"]["ks"] <= 1
    assert any(p.endswith("pdf_displacement.png") for p in ours["written"])
    cli("compare", "a.h5", "b.h5", "--window", "2:4", "--label-a", "mu 0.1", "--label-b",
        "mu 0.5", "--out", "cli")
    a = pd.read_csv(tmp_path / "py" / "distances.csv", comment="#")
    b = pd.read_csv(tmp_path / "cli" / "distances.csv", comment="#")
    pd.testing.assert_frame_equal(a, b)
