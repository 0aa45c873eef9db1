"""granmem.calibrate: the command line's friction fit from Python, stopped and resumed."""
import json

import numpy as np
import pytest

import granmem

# A tiny pseudo-experiment and its twin's protocol: 60 grains in a 2 cm box, 3 cycles.
TWIN = dict(grains=60, box="2cm", lid_mass="0.2kg", amplitude="5%", period="0.1s")
TWIN_FLAGS = ["--grains", "60", "--box", "2cm", "--lid-mass", "0.2kg", "--amplitude", "5%",
              "--period", "0.1s", "--replicas", "2"]
FIT = dict(mu_s=[0.05, 0.1, 0.2, 0.4], window=(2, 3), observables="steady-state",
           fit_only=True, parallel=2, replicas=2)


@pytest.fixture
def experiment(tmp_path):
    granmem.simulate(out=tmp_path / "exp.h5", cycles=3, seed=7, mu_s=0.2, threads=1, **TWIN)
    return tmp_path / "exp.h5"


def test_calibrate_in_python_equals_the_command_line(tmp_path, cli, experiment):
    lines = []
    fit = granmem.calibrate(experiment, tmp_path / "py", progress=lines.append, **FIT, **TWIN)
    assert fit["true_mu_s"] == 0.2  # a pseudo-experiment says its friction
    lo, hi = fit["mu_s_ci95"]
    assert lo <= fit["mu_s"] <= hi
    assert fit["simulations"] == 8  # 4 frictions x 2 packings, none at the fit (fit_only)
    assert any("cycle" in r for r in lines) and any("8 runs" in r.get("line", "") for r in lines)
    out = cli("calibrate", "--experiment", "exp.h5", "--out", "cli", "--mu-s", "0.05,0.1,0.2,0.4",
              "--window", "2:3", "--observables", "steady-state", "--fit-only", *TWIN_FLAGS)
    def fitted(report):  # the lines but the last, which names the output folder
        return report.splitlines()[:-1]
    assert fitted(out) == fitted(fit["report"]) and "mu_s = " in out
    ours = json.loads((tmp_path / "py" / "summary.json").read_text())
    theirs = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert ours["mu_s"] == theirs["mu_s"] == fit["mu_s"]
    assert ours["mu_s_ci95"] == theirs["mu_s_ci95"]
    assert ours["settings"] == theirs["settings"]


def test_the_window_chosen_from_the_runs_is_the_command_lines(tmp_path, cli, experiment):
    auto = dict(FIT, window="auto")
    fit = granmem.calibrate(experiment, tmp_path / "py", **auto, **TWIN)
    assert "window from the twin's runs: cycles " in fit["report"]
    out = cli("calibrate", "--experiment", "exp.h5", "--out", "cli", "--mu-s", "0.05,0.1,0.2,0.4",
              "--window", "auto", "--observables", "steady-state", "--fit-only", *TWIN_FLAGS)
    assert out.splitlines()[:-1] == fit["report"].splitlines()[:-1]


def test_a_refined_design_is_the_command_lines(tmp_path, cli, experiment):
    # with a scan's axis error given to the twin's axes, as the command line's --axis-noise
    fit = granmem.calibrate(experiment, tmp_path / "py", **dict(FIT, refine=2, axis_noise=1),
                            **TWIN)
    assert fit["simulations"] == 10  # 4 frictions x 2 packings, and 2 packings at their fit
    assert "packing(s) more at mu_s " in fit["report"]
    out = cli("calibrate", "--experiment", "exp.h5", "--out", "cli", "--mu-s", "0.05,0.1,0.2,0.4",
              "--window", "2:3", "--observables", "steady-state", "--fit-only", "--refine", "2",
              "--axis-noise", "1", *TWIN_FLAGS)
    assert out.splitlines()[:-1] == fit["report"].splitlines()[:-1]
    summary = json.loads((tmp_path / "py" / "summary.json").read_text())
    assert summary["axis_noise_deg"] == 1


def test_the_axis_noise_is_read_from_the_scans_standard_errors(tmp_path, experiment):
    # The pseudo-experiment as tracked scans would give it: positions, hole axes (the body z
    # axis) and each axis' standard error, 1 deg for every grain, its RMS then 1 deg.
    tracks = granmem.read_tracks(experiment)
    w, x, y, z = (tracks[c] for c in ("qw", "qx", "qy", "qz"))
    tracks["ax"], tracks["ay"] = 2 * (x * z + w * y), 2 * (y * z - w * x)
    tracks["az"] = 1 - 2 * (x * x + y * y)
    tracks["axis_error"] = np.radians(1.0)
    scans = tmp_path / "scans.h5"
    granmem.write_run(tracks.drop(columns=["qw", "qx", "qy", "qz"]), scans, length_unit="m")
    assert granmem.read_run(scans)["axis_error"].shape == (4, 60)
    lines = []
    auto = granmem.calibrate(scans, tmp_path / "cal", progress=lines.append, **FIT, **TWIN)
    summary = json.loads((tmp_path / "cal" / "summary.json").read_text())
    assert summary["axis_noise_deg"] == pytest.approx(1, rel=1e-12)
    assert summary["axis_noise_from"] == "experiment"
    assert any("tilted by 1 deg (the experiment's RMS axis standard error)" in r.get("line", "")
               for r in lines)
    given = granmem.calibrate(scans, tmp_path / "cal", **dict(FIT, axis_noise=1), **TWIN)
    # the same noise, to the rounding of an RMS
    assert given["mu_s"] == pytest.approx(auto["mu_s"], rel=1e-6)
    none = granmem.calibrate(scans, tmp_path / "cal", **dict(FIT, axis_noise=0), **TWIN)
    assert none["mu_s"] != auto["mu_s"]
    # Axes without their errors (another program's tracks): exact in the twin, and said;
    # the same fit as the scans' with the twin's axes exact (both observables kept: the
    # noise check would leave the scans' rotation out, as their axes carry an error).
    bare = tmp_path / "bare.h5"
    granmem.write_run(tracks.drop(columns=["qw", "qx", "qy", "qz", "axis_error"]), bare,
                      length_unit="m")
    lines = []
    both = dict(FIT, only=["dr", "rot_disp"])
    exact = granmem.calibrate(bare, tmp_path / "cal", progress=lines.append, **both, **TWIN)
    none = granmem.calibrate(scans, tmp_path / "cal", **dict(both, axis_noise=0), **TWIN)
    assert exact["mu_s"] == none["mu_s"]
    assert any("carry no standard errors" in r.get("line", "") for r in lines)


def test_what_the_scans_locating_noise_moves_is_left_out(tmp_path, cli, experiment):
    # The pseudo-experiment as scans locating centres to 0.1 mm (2 % of a diameter, said
    # by their standard errors), imported in the container's frame. The height of 60 grains
    # is a few grains' tops and bottoms, which such noise moves (the highest of a few noisy
    # tops is higher) by most of one packing's scatter: the twin, exact, would not see it;
    # nor the displacements, each the difference of two such positions.
    tracks = granmem.read_tracks(experiment).drop(columns=["qw", "qx", "qy", "qz"])
    lo, hi = granmem.read_run(experiment)["box"]
    rng = np.random.default_rng(3)

    def scans(sigma, name, missed=()):
        located = tracks.copy()
        for c in ("x", "y", "z"):
            located[c] += rng.normal(0, sigma, len(located))
            located["ep_" + c] = sigma
        located.drop(index=list(missed)).to_csv(tmp_path / (name + ".csv"), index=False)
        cli("import", name + ".csv", "--out", name + ".h5", "--length-unit", "m",
            "--container", ",".join(str(v) for v in (*lo, *hi)))
        return tmp_path / (name + ".h5")

    lines = []
    noisy = granmem.calibrate(scans(1e-4, "noisy", missed=[5]), tmp_path / "cal",
                              progress=lines.append, **FIT, **TWIN)
    summary = json.loads((tmp_path / "cal" / "summary.json").read_text())
    assert summary["left_out_for_scan_noise"] == ["dr", "height_packing_fraction"]
    assert list(summary["observables"]) == ["rot_disp"]
    assert "height_packing_fraction left out: the scans' own locating noise moves it by" \
        in noisy["report"]
    assert any("locate 59-60 grains, the twin pours 60" in r.get("line", "") for r in lines)
    # located to 1 um, the same (poured) twin keeps it; and --only keeps it whatever the noise.
    # (A twin placed from such scans would not: its packings, one packing jittered by 0.5 um,
    # scatter less than even 1 um of noise moves the height of 60 grains.)
    sharp = granmem.calibrate(scans(1e-6, "sharp"), tmp_path / "cal", deposit="each", **FIT,
                              **TWIN)
    assert "left out" not in sharp["report"]
    only = dict(FIT, only=["rot_disp", "height_packing_fraction"])
    kept = granmem.calibrate(tmp_path / "noisy.h5", tmp_path / "cal", **only, **TWIN)
    assert "left out" not in kept["report"]


def test_the_scans_contacts_say_their_actual_noise(tmp_path, cli, experiment):
    # Scans in voxels of 0.1 mm whose centres err by 0.2 mm (4 % of a diameter) while their
    # standard errors say 1 um: the touching neighbours' spread reads the actual error. Their
    # standard errors being fine, the twin is placed from them by default, and the contacts,
    # read against its run, say that it leans. The twin's positions are given the error the
    # contacts read before their structure is measured, so the height the noise moves is
    # fitted as the scans see it, not left out; poured, the fit holds the true friction.
    voxel, sigma = 1e-4, 2e-4
    tracks = granmem.read_tracks(experiment).drop(columns=["qw", "qx", "qy", "qz"])
    lo, hi = granmem.read_run(experiment)["box"]
    rng = np.random.default_rng(5)
    for c in ("x", "y", "z"):
        tracks[c] = (tracks[c] + rng.normal(0, sigma, len(tracks))) / voxel
        tracks["ep_" + c] = 1e-6 / voxel
    tracks["radius"] /= voxel
    tracks.to_csv(tmp_path / "scans.csv", index=False)
    cli("import", "scans.csv", "--out", "scans.h5", "--voxel-size", "0.1mm",
        "--container", ",".join(str(v / voxel) for v in (*lo, *hi)))
    for deposit in ("auto", "each"):
        out = tmp_path / deposit
        # placed from the frame before the window, as this test measured it (from their
        # preparation, cycle 0, the default for scans, the height this 0.2 mm noise moves is
        # more than the twin's moved positions model there, and is left out)
        start = dict(placed_cycle="1") if deposit == "auto" else {}
        fit = granmem.calibrate(tmp_path / "scans.h5", out, true_mu_s=0.2, deposit=deposit,
                                **start, **FIT, **TWIN)
        assert fit["true_mu_s"] == 0.2  # given: scans drawn from a simulation do not carry it
        summary = json.loads((out / "summary.json").read_text())
        contacts = summary["locating_error_from_contacts"]
        assert 130 < contacts["across_um"] < 300 and 130 < contacts["along_z_um"] < 300
        placed = deposit == "auto"
        assert summary["deposit"] == ("experiment" if placed else "each")
        assert ("more than 0.003 d: the twin's packings settle denser" in fit["report"]) == placed
        assert contacts["given_to_twin"]
        assert "the twin's positions were given this error before their structure was " \
            "measured" in fit["report"]
        assert "height_packing_fraction" in summary["observables"]
        # the displacements, which the twin's positions' noise does not model, are left out
        assert summary["left_out_for_scan_noise"] == ["dr"]
    lo, hi = fit["mu_s_ci95"]
    assert lo < 0.2 < hi and hi / lo < 3


def test_a_rotation_made_of_axis_noise_is_left_out(tmp_path, cli, experiment):
    # Hole axes known to 30 deg: the measured rotation is the noise's, more than the twin's
    # tilted axes model to the accuracy of that noise's size; known to 1 deg, it is kept.
    # Imported in the container's frame, exact positions: the height is fitted either way.
    tracks = granmem.read_tracks(experiment)
    w, x, y, z = (tracks[c] for c in ("qw", "qx", "qy", "qz"))
    tracks["ax"], tracks["ay"] = 2 * (x * z + w * y), 2 * (y * z - w * x)
    tracks["az"] = 1 - 2 * (x * x + y * y)
    tracks = tracks.drop(columns=["qw", "qx", "qy", "qz"])
    lo, hi = granmem.read_run(experiment)["box"]
    for deg, left_out in ((30, ["rot_disp"]), (1, [])):
        tracks.assign(axis_error=np.radians(deg)).to_csv(tmp_path / f"scans{deg}.csv",
                                                         index=False)
        cli("import", f"scans{deg}.csv", "--out", f"scans{deg}.h5", "--length-unit", "m",
            "--container", ",".join(str(v) for v in (*lo, *hi)))
        fit = granmem.calibrate(tmp_path / f"scans{deg}.h5", tmp_path / f"cal{deg}", **FIT,
                                **TWIN)
        summary = json.loads((tmp_path / f"cal{deg}" / "summary.json").read_text())
        assert summary["left_out_for_scan_noise"] == left_out
        assert ("rot_disp" in summary["observables"]) == (not left_out)
        assert "height_packing_fraction" in summary["observables"]
    assert "rot_disp left out: the scans' own axis noise moves it by" in granmem.calibrate(
        tmp_path / "scans30.h5", tmp_path / "cal30", **FIT, **TWIN)["report"]


def test_one_cycle_ahead_is_the_command_lines(tmp_path, cli, experiment):
    ahead = dict(FIT, mu_s=[0.1, 0.2, 0.4], window=(1, 3), fit_only=False, one_cycle_ahead=True,
                 ahead_burn_in=0)
    fit = granmem.calibrate(experiment, tmp_path / "py", **ahead, **TWIN)
    assert fit["simulations"] == 10  # 3 frictions x 2 packings, and the packing ahead at 4
    lo, hi = fit["mu_s_ci95"]
    assert lo <= 0.2 <= hi
    out = cli("calibrate", "--experiment", "exp.h5", "--out", "cli", "--mu-s", "0.1,0.2,0.4",
              "--window", "1:3", "--one-cycle-ahead", "--ahead-burn-in", "0", *TWIN_FLAGS)
    assert out.splitlines()[:-1] == fit["report"].splitlines()[:-1]
    assert "3 cycles' own fits" in out


def test_a_stopped_calibration_reuses_its_finished_runs(tmp_path, experiment):
    def stop_at_first_report(report):
        if "cycle" in report:
            raise KeyboardInterrupt  # as Ctrl-C would

    with pytest.raises(KeyboardInterrupt):
        granmem.calibrate(experiment, tmp_path / "cal", progress=stop_at_first_report,
                          **FIT, **TWIN)
    lines = []
    fit = granmem.calibrate(experiment, tmp_path / "cal", progress=lines.append, **FIT, **TWIN)
    assert fit["simulations"] == 8
    assert fit["mu_s_ci95"][0] <= fit["mu_s"] <= fit["mu_s_ci95"][1]


def test_bad_calibrations_are_one_clear_error(tmp_path, experiment):
    with pytest.raises(granmem.Error, match="'cycles' is not a setting of the twin"):
        granmem.calibrate(experiment, tmp_path / "x", cycles=3, **FIT)
    with pytest.raises(granmem.Error, match="mu-s: 2 frictions; the fit needs at least 3"):
        granmem.calibrate(experiment, tmp_path / "x", mu_s=[0.1, 0.2], **TWIN)
    with pytest.raises(granmem.Error, match="twin has 3%"):
        granmem.calibrate(experiment, tmp_path / "x", **{**FIT, **TWIN, "amplitude": "3%"})
    with pytest.raises(granmem.Error, match="deposit 'poured': expected each, shared, experiment or auto"):
        granmem.calibrate(experiment, tmp_path / "x", deposit="poured", **FIT, **TWIN)
    with pytest.raises(granmem.Error, match="placed-jitter: a length > 0"):
        granmem.calibrate(experiment, tmp_path / "x", deposit="experiment", placed_jitter=0,
                          **FIT, **TWIN)
    with pytest.raises(granmem.Error, match="placed_cycle 'first': expected auto or a cycle"):
        granmem.calibrate(experiment, tmp_path / "x", deposit="experiment", placed_cycle="first",
                          **FIT, **TWIN)
    with pytest.raises(granmem.Error, match="placed-cycle 0: only for a twin placed from the experiment; this one is --deposit each"):
        granmem.calibrate(experiment, tmp_path / "x", deposit="each", placed_cycle=0,
                          **FIT, **TWIN)
    assert not (tmp_path / "x").exists()  # refused before any output
