"""Scans -> tracks -> displacements from Python, checked against the motion put in."""
import pathlib

import numpy as np
import pandas as pd
import pytest

import granmem
from conftest import lattice

SHIFT = np.array([0.3, -0.2, 0.1])  # mm, with each grain's own jitter on top


def moved_lattice():
    """Frame 0, then every grain moved by SHIFT plus up to 0.1 mm of its own."""
    first = lattice(seed=1)
    rng = np.random.default_rng(9)
    second = first.copy()
    own = rng.uniform(-0.1, 0.1, (len(first), 3))
    second[["x", "y", "z"]] += SHIFT + own
    return first, second, SHIFT + own


def test_scans_to_displacements_recover_the_motion_put_in():
    first, second, truth = moved_lattice()
    # Each scan's voxel (0,0,0) sits at the grains' extent less a margin, which moves with
    # them: the detections are put back into the grains' frame from the render's truth.
    detections = []
    for k, grains in enumerate([first, second]):
        stack, voxel, truth_table = granmem.render(grains, length_unit="mm", diameter_px=10,
                                                   seed=k + 1)
        d = granmem.locate(stack, diameter="5mm", voxel_size=voxel, unit="mm", frame=k)
        # Back to the grains' frame: the truth gives where voxel (0,0,0) was.
        grain_mm = grains[["x", "y", "z"]].to_numpy()[0]
        origin = grain_mm - truth_table[["x", "y", "z"]].to_numpy()[0] * np.asarray(voxel)
        d[["x", "y", "z"]] += origin
        detections.append(d)
    tracks = granmem.link(detections)
    assert tracks.attrs["length_unit"] == "mm"
    # locate's standard errors go with each grain into its track: a centre to a small
    # fraction of a voxel (0.5 mm), each axis to a degree or so.
    for column in ("ep_x", "ep_y", "ep_z", "axis_error"):
        np.testing.assert_array_equal(np.sort(tracks[column]),
                                      np.sort(pd.concat(detections)[column]))
    assert 0 < tracks[["ep_x", "ep_y", "ep_z"]].to_numpy().max() < 0.05
    assert 0 < np.nanmedian(np.degrees(tracks["axis_error"])) < 2
    assert tracks.attrs["summary"]["tracks"] == 18
    assert tracks.attrs["summary"]["scans"][1]["linked_fraction"] == 1.0
    moved = granmem.motion(tracks, before=0, after=1)
    assert len(moved) == 18
    # Tracks are numbered in order of first appearance: match them to the truth by place.
    start = tracks[tracks.frame == 0].set_index("particle")[["x", "y", "z"]]
    d_true = {}
    for p, row in start.iterrows():
        k = np.argmin(np.linalg.norm(first[["x", "y", "z"]].to_numpy() - row.to_numpy(), axis=1))
        d_true[p] = truth[k]
    expected = np.array([d_true[p] for p in moved.particle])
    error = moved[["dx", "dy", "dz"]].to_numpy() - expected
    assert np.sqrt(np.mean(error ** 2)) < 0.05  # mm: a tenth of a voxel
    # The drift removed is the mean motion.
    still = granmem.motion(tracks, before=0, after=1, subtract_drift=True)
    assert np.asarray(still.attrs["drift"]) == pytest.approx(expected.mean(axis=0), abs=0.02)
    assert still[["dx", "dy", "dz"]].mean().to_numpy() == pytest.approx(0, abs=1e-12)


def test_a_trackpy_table_links_to_the_true_identities():
    first, second, _ = moved_lattice()
    # trackpy's shape: frame, x, y, z only, shuffled within each frame.
    table = pd.concat([first.assign(frame=0), second.assign(frame=1)])
    truth_id = table["particle"].to_numpy()
    table = table[["frame", "x", "y", "z"]].sample(frac=1, random_state=4)
    truth_id = truth_id[table.index.to_numpy() + np.where(table.frame == 1, len(first), 0)]
    tracks = granmem.link(table, length_unit="mm", max_displacement="1mm")
    assert len(tracks) == 36
    # Each track holds one true grain in both frames.
    rows = {(f, round(x, 9)): tid for f, x, tid in zip(table.frame, table.x, truth_id)}
    owner = {}
    for f, p, x in zip(tracks.frame, tracks.particle, tracks.x):
        owner.setdefault(p, set()).add(rows[(f, round(x, 9))])
    assert all(len(ids) == 1 for ids in owner.values())
    assert len(owner) == 18


def test_link_reports_each_scan_and_stops_on_ctrl_c():
    first, second, _ = moved_lattice()
    xyz = ["x", "y", "z"]
    scans = [first[xyz].assign(frame=k) for k in range(3)] + [second[xyz].assign(frame=3)]
    lines = []
    granmem.link(scans, length_unit="mm", max_displacement="1mm",
                 progress=lambda r: lines.append(r["line"]))
    assert lines == ["linking scan 2 of 4", "linking scan 3 of 4", "linking scan 4 of 4"]

    def stop(report):
        raise KeyboardInterrupt  # as Ctrl-C would, between two scans
    with pytest.raises(KeyboardInterrupt):
        granmem.link(scans, length_unit="mm", max_displacement="1mm", progress=stop)


def test_store_round_trip_and_the_command_line_agree(tmp_path, cli):
    first, second, _ = moved_lattice()
    table = pd.concat([first.assign(frame=0), second.assign(frame=1)])
    granmem.write_run(table, tmp_path / "run.h5", length_unit="mm")
    run = granmem.read_run(tmp_path / "run.h5")
    assert run["position"].shape == (2, 18, 3)
    assert run["length_unit"] == "mm"
    np.testing.assert_array_equal(run["id"], np.sort(first.particle))
    np.testing.assert_array_equal(run["position"][1], second.sort_values("particle")[["x", "y", "z"]])
    tracks = granmem.read_tracks(tmp_path / "run.h5")
    cli("export", "run.h5", "--out", "tracks.csv")
    from_cli = pd.read_csv(tmp_path / "tracks.csv", comment="#")
    assert list(from_cli.columns) == list(tracks.columns)
    for c in tracks.columns:
        np.testing.assert_allclose(tracks[c], from_cli[c], rtol=1e-12, err_msg=c)
    # Motion from the store and from the DataFrame: one implementation.
    a = granmem.motion(tmp_path / "run.h5", 0, 1)
    b = granmem.motion(tracks, 0, 1)
    pd.testing.assert_frame_equal(a, b)
    assert "theta_axis" in a.columns  # the table had cavity axes


def test_the_apparatus_readings_are_stored_with_the_tracks(tmp_path, cli):
    first, second, _ = moved_lattice()
    table = pd.concat([first.assign(frame=0), second.assign(frame=1)])
    (tmp_path / "readings.csv").write_text("cycle,wall_force_full_compression\n0,11.5\n1,12.0\n")
    granmem.write_run(table, tmp_path / "run.h5", length_unit="mm",
                      readings=tmp_path / "readings.csv")
    force = granmem.read_run(tmp_path / "run.h5")["observables"]["wall_force_full_compression"]
    np.testing.assert_array_equal(force["value"], [11.5, 12.0])
    np.testing.assert_array_equal(force["step"], [0, 1])
    # The command line's import stores the same.
    table.to_csv(tmp_path / "tracks.csv", index=False)
    cli("import", "tracks.csv", "--length-unit", "mm", "--readings", "readings.csv",
        "--out", "cli.h5")
    same = granmem.read_run(tmp_path / "cli.h5")["observables"]["wall_force_full_compression"]
    np.testing.assert_array_equal(same["value"], force["value"])
    (tmp_path / "readings.csv").write_text("cycle,wall_force_unloaded\n1,-2\n")
    with pytest.raises(granmem.Error, match="expected a force >= 0 in N"):
        granmem.write_run(table, tmp_path / "x.h5", length_unit="mm",
                          readings=tmp_path / "readings.csv")
    assert not (tmp_path / "x.h5").exists()


def test_bad_tables_are_one_clear_error(tmp_path):
    with pytest.raises(granmem.Error, match="no column 'particle'"):
        granmem.write_run(pd.DataFrame({"frame": [0], "x": [1.0], "y": [1.0], "z": [1.0]}),
                          tmp_path / "x.h5", length_unit="mm")
    with pytest.raises(granmem.Error, match="no frame 5"):
        granmem.motion(lattice().assign(frame=0), 0, 5, length_unit="mm")
    assert not (tmp_path / "x.h5").exists()


def test_analyze_in_python_equals_the_command_line(tmp_path, cli):
    sample = pathlib.Path(__file__).resolve().parents[2] / "sample_data" / "tracked_grains.csv"
    cli("import", sample, "--out", "run.h5", "--length-unit", "voxel",
        "--voxel-size", "0.41667,0.41667,0.625mm")
    cli("analyze", "run.h5", "--out", "a", "--subtract-drift", "--hole-contacts",
        "exclude-rotations", "--window", "6:15", "--pdf-scale", "log")
    a = granmem.analyze(tmp_path / "run.h5", subtract_drift=True,
                        hole_contacts="exclude-rotations", window=(6, 15), pdf_scale="log")
    assert a["per_frame"].attrs["length_unit"] == "mm"
    for name in ["displacements", "per_frame", "pdf_dr", "pdf_theta_axis_deg"]:
        from_cli = pd.read_csv(tmp_path / "a" / f"{name}.csv", comment="#")
        ours = a["pdfs"][name[4:]] if name.startswith("pdf_") else a[name]
        assert list(from_cli.columns) == list(ours.columns), name
        for c in ours.columns:
            np.testing.assert_allclose(ours[c], from_cli[c], rtol=1e-12, equal_nan=True,
                                       err_msg=f"{name}.{c}")
    # Fifteen frame pairs of 800 grains, most seen in both frames of a pair.
    assert len(a["per_frame"]) == 15
    assert len(a["displacements"]) > 15 * 780
