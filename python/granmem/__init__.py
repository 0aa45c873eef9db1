"""granmem from Python: scans to grains to tracks to displacements, with numpy and pandas.

Stacks are numpy arrays (z, y, x) of uint8 or uint16 with a voxel size (x, y, z) and its
unit; grains, tracks and displacements are pandas DataFrames with trackpy's column names
(frame, particle, x, y, z, ...), lengths in ``df.attrs["length_unit"]``. Lengths given as
options may carry a unit as text ("0.4mm"); a bare number is in the data's unit. The work
is done by granmem's C++ libraries, the same code as the ``granmem`` command line.

    import granmem
    stack, voxel_size, unit = granmem.read_stack("scan0.tif")
    grains = granmem.locate(stack, diameter="5mm", voxel_size=voxel_size, unit=unit)
    tracks = granmem.link([grains0, grains1, grains2])
    moved = granmem.motion(tracks, before=0, after=1, subtract_drift=True)
"""

import os

import numpy as np
import pandas as pd

from . import _granmem
from ._granmem import Error

__version__ = _granmem.__version__

__all__ = ["Error", "read_stack", "write_tiff", "render", "locate", "link", "read_run",
           "read_tracks", "write_run", "motion", "analyze", "simulate", "readout", "compare",
           "calibrate", "set_author"]


def _frame(columns, units=None, **attrs):
    df = pd.DataFrame(columns)
    df.attrs.update(attrs)
    if units is not None:
        df.attrs["units"] = {k: v for k, v in units.items() if v}
    return df


def _columns(df, names=None):
    """A DataFrame's numeric columns as a dict of float arrays (what the libraries read)."""
    names = df.columns if names is None else [c for c in names if c in df.columns]
    return {str(c): np.asarray(df[c], dtype=float) for c in names}


def _length(value):
    return value if isinstance(value, str) else repr(float(value))


def _vector3(value):
    if value is None:
        return None
    v = np.broadcast_to(np.asarray(value, dtype=float), (3,))
    return tuple(float(x) for x in v)


def read_stack(path, dataset="", region=None):
    """Reads a scan (multi-page TIFF, folder of slices, or HDF5 ``dataset``); ``region``
    "x0,y0,z0,nx,ny,nz" (voxels) reads only that box, as ``granmem locate --region``.

    Returns ``(stack, voxel_size, unit)``: the (z, y, x) array, the voxel size (x, y, z) or
    None when the file does not say, and its unit."""
    return _granmem.read_stack(os.fspath(path), dataset,
                               None if region is None else str(region))


def write_tiff(stack, path, voxel_size=None, unit=""):
    """Writes a (z, y, x) uint8/uint16 array as a multi-page TIFF with ImageJ's voxel size."""
    _granmem.write_tiff(stack, os.fspath(path), _vector3(voxel_size), unit)


def render(grains, length_unit="m", diameter_px=20, slice_spacing_ratio=1, clean=False,
           hole_fraction=0.3, polarity="dark", bits=8, seed=1, frame=0):
    """Renders a laser-sheet scan of grains (a DataFrame with x, y, z, radius and optionally
    particle, ax, ay, az), as ``granmem render`` does.

    Returns ``(stack, voxel_size, truth)``: the (z, y, x) array, its voxel size (x, y, z) in
    ``length_unit`` and the truth (voxel coordinates) as a DataFrame. ``clean`` leaves out
    the blur, the uneven light and the noise."""
    stack, voxel_size, truth = _granmem.render(
        _columns(grains, ["particle", "x", "y", "z", "radius", "ax", "ay", "az"]),
        length_unit, float(diameter_px), float(slice_spacing_ratio), bool(clean),
        float(hole_fraction), polarity, int(bits), int(seed), int(frame))
    return stack, voxel_size, _frame(truth, length_unit="voxel")


def locate(stack, diameter, voxel_size=None, unit="", frame=0, polarity="dark",
           hole_fraction=0.3, beam="x", axis="fit", passes=4, illumination=True, progress=None):
    """Every grain of one scan: centre, radius, hole axis and quality, as ``granmem locate``.

    ``stack`` is a (z, y, x) uint8/uint16 array (left unchanged); ``diameter`` in voxels
    along x (12) or a length ("5mm") with ``voxel_size`` (x, y, z) in ``unit``. Returns a
    DataFrame: frame, particle (the detection's index), x, y, z, radius, quality, edge,
    ep_x, ep_y, ep_z (the centre's standard errors), and with holes ax, ay, az,
    axis_quality, axis_error (rad), hole_contact; lengths in ``attrs["length_unit"]``
    (the voxel size's unit, or voxels), the run's numbers in ``attrs["summary"]``.
    ``progress``: called with a dict ``{"line": stage}`` as each stage begins; Ctrl-C stops
    between two stages (KeyboardInterrupt)."""
    columns, units, summary = _granmem.locate(
        stack, str(diameter), _vector3(voxel_size), unit, int(frame), polarity,
        float(hole_fraction), beam, axis, int(passes), bool(illumination), progress)
    return _frame(columns, units, length_unit=summary["length_unit"],
                  voxel_size=summary["voxel_size"], summary=summary)


def _scans(detections):
    """A list of per-scan DataFrames, or one DataFrame with a frame column, -> [(columns, frame)]."""
    if isinstance(detections, pd.DataFrame):
        if "frame" not in detections.columns:
            raise Error("link: the detections have no 'frame' column")
        parts = [g for _, g in detections.groupby("frame", sort=True)]
    else:
        parts = list(detections)
    scans = []
    for k, df in enumerate(parts):
        frame = int(df["frame"].iloc[0]) if "frame" in df.columns and len(df) else k
        columns = _columns(df, ["x", "y", "z", "radius", "quality", "edge", "ep", "ep_x",
                                "ep_y", "ep_z", "ax", "ay", "az", "axis_quality", "axis_error",
                                "hole_contact"])
        n = len(df)
        # trackpy's tables have no radius, quality or edge: unknown, good, inside.
        columns.setdefault("radius", np.full(n, np.nan))
        columns.setdefault("quality", np.ones(n))
        columns.setdefault("edge", np.zeros(n))
        scans.append((columns, frame))
    return scans, parts


def link(detections, length_unit=None, voxel_size=None, max_displacement="auto", memory=2,
         collective_motion=True, container=None, container_size=None, progress=None):
    """Links the detections of successive scans into tracks, as ``granmem link``.

    ``detections``: a list of DataFrames, one per scan in order (e.g. from ``locate``), or
    one DataFrame with a frame column (trackpy's shape). Returns the tracks as a DataFrame:
    frame, particle (the track), time, x, y, z, radius, and ax, ay, az, hole_contact where
    the scans have axes, ep_x, ep_y, ep_z and axis_error where they have standard errors. ``container`` ("xmin,ymin,zmin,xmax,ymax,zmax cm") or
    ``container_size`` ("LX,LY,LZ cm", placed at the packing's extent in the first scan)
    moves the positions into the container's frame. ``collective_motion=False``: no
    estimate of the packing's drift and deformation between scans (``--no-collective-motion``).
    ``progress``: called with ``{"line": "linking scan k of n"}`` as each scan begins; Ctrl-C
    stops between two scans (KeyboardInterrupt)."""
    scans, parts = _scans(detections)
    if length_unit is None:
        length_unit = parts[0].attrs.get("length_unit", "voxel") if parts else "voxel"
    if voxel_size is None and parts:
        voxel_size = parts[0].attrs.get("voxel_size")
    columns, units, summary = _granmem.link(
        scans, length_unit, _vector3(voxel_size), _length(max_displacement) if
        max_displacement != "auto" else "auto", int(memory), bool(collective_motion), container,
        container_size, progress)
    return _frame(columns, units, length_unit=length_unit, summary=summary)


def set_author(name):
    """Who made the files: recorded in every store written from now on (H5MD's
    /h5md/author, as ``granmem --author``); the login name until set."""
    _granmem.set_author(str(name))


def info(path):
    """What a trajectory store holds, as ``granmem info`` prints it."""
    return _granmem.info(os.fspath(path))


def read_run(path):
    """A trajectory store (.h5, H5MD) as a dict of numpy arrays: position (frames, grains,
    3; NaN where not seen), axis, orientation, position_error (frames, grains, 3) and
    axis_error (frames, grains; rad), a scan's standard errors (or None), id, radius, step, time, box,
    length_unit, time_unit, parameters, and observables (name -> unit, step, time, value)."""
    return _granmem.read_run(os.fspath(path))


def read_tracks(path):
    """A trajectory store as trackpy's long DataFrame: a row per grain seen in each frame."""
    columns, units = _granmem.track_table(os.fspath(path))
    run_unit = units.get("x", "")
    return _frame(columns, units, length_unit=run_unit)


def write_run(tracks, path, length_unit=None, radius=None, readings=None):
    """Writes tracks (frame, particle, x, y, z and optionally radius, ax, ay, az,
    hole_contact, the standard errors ep_x, ep_y, ep_z or trackpy's ep, and axis_error in
    rad) as a trajectory store that ``granmem analyze``, ``compare`` and
    ``calibrate`` read; written atomically. ``radius``: of every grain, for tables without
    a radius column. ``readings``: a CSV of the apparatus' readings, cycle by cycle (columns
    cycle and wall_force_full_compression and/or wall_force_unloaded, in N), stored with
    the tracks as ``--readings`` does on the command line."""
    unit = length_unit or tracks.attrs.get("length_unit", "voxel")
    names = ["frame", "particle", "x", "y", "z", "radius", "ax", "ay", "az", "hole_contact",
             "ep", "ep_x", "ep_y", "ep_z", "axis_error"]
    _granmem.write_run(_columns(tracks, names), os.fspath(path), unit,
                       None if radius is None else float(radius),
                       None if readings is None else os.fspath(readings))


def motion(run, before, after, subtract_drift=False, wall_distance=0,
           hole_contacts="keep", length_unit=None):
    """How each grain moved from frame ``before`` to frame ``after`` (frame labels), as
    ``granmem analyze`` measures it: particle, dx, dy, dz, dr, and with axes or
    orientations theta_axis (rad), rot_disp, theta_full (rad).

    ``run``: a trajectory store's path, or tracks as a DataFrame. ``wall_distance`` leaves
    out grains that near a face of the run's box; ``hole_contacts``: keep,
    exclude-rotations (the paper's choice for scans) or exclude. The removed drift is in
    ``attrs["drift"]``."""
    if isinstance(run, pd.DataFrame):
        unit = length_unit or run.attrs.get("length_unit", "voxel")
        names = ["frame", "particle", "x", "y", "z", "radius", "ax", "ay", "az", "hole_contact"]
        out = _granmem.motion_of_table(_columns(run, names), unit, int(before), int(after),
                                       bool(subtract_drift), _length(wall_distance),
                                       hole_contacts)
    else:
        out = _granmem.motion_of_run(os.fspath(run), int(before), int(after),
                                     bool(subtract_drift), _length(wall_distance),
                                     hole_contacts)
        unit = out["units"].get("dx", "")
    return _frame(out["columns"], out["units"], length_unit=unit, drift=out["drift"])


def _range(value):
    if value is None or isinstance(value, str):
        return value
    lo, hi = value
    return f"{lo}:{hi}"


def analyze(run, subtract_drift=False, wall_distance=0, container=None, hole_contacts="keep",
            pdf=(), window=None, pdf_bins=50, pdf_scale="linear", pdf_range=None):
    """The paper's statistics of a run between consecutive frames, as ``granmem analyze``
    (the same tables as its CSV files), for a trajectory store's path.

    Returns a dict: ``displacements`` (a row per grain per frame pair), ``per_frame``
    (means, medians, MSD, drift, packing fraction, coordination), ``pdfs`` (quantity ->
    DataFrame of bins) as DataFrames, and ``notes`` (what was left out and why).
    ``window`` (the frames pooled into the pdfs) and ``pdf_range`` as ``(lo, hi)`` or
    "lo:hi"; ``container`` as "xmin,ymin,zmin,xmax,ymax,zmax"."""
    out = _granmem.analyze(os.fspath(run), bool(subtract_drift), _length(wall_distance), container,
                           hole_contacts, list(pdf), _range(window), int(pdf_bins),
                           pdf_scale, _range(pdf_range))
    unit = out["length_unit"]
    tables = {name: _frame(*out[name], length_unit=unit) for name in ("displacements",
                                                                       "per_frame")}
    tables["pdfs"] = {q: _frame(*t, length_unit=unit) for q, t in out["pdfs"].items()}
    tables["notes"] = out["notes"]
    return tables


def simulate(out=None, resume=None, start_from=None, threads=0, progress=None,
             **settings):
    """The embedded DEM (or LAMMPS, ``engine="lammps"``: docs/LAMMPS.md), as ``granmem
    simulate``: grains deposited under a lid (or a packing from ``start_from``'s
    checkpoint) and compressed cyclically; the end-of-cycle store at ``out`` (read it with
    ``read_run`` or ``analyze``) and a checkpoint beside it.

    ``settings``: simulate's options with ``_`` for ``-`` and their units as text, e.g.
    ``grains=1500, box="5cm", lid_pressure="436Pa", amplitude="1%", mu_s=0.15, cycles=40``
    (``granmem simulate --help`` lists them; the defaults are the paper's). ``resume``
    continues a checkpoint's run (``cycles`` may be raised). ``progress(report)`` is called
    with a dict: a ``line`` of what the run does, or ``cycle``, ``cycles``,
    ``particle_steps_per_second``, ``seconds_left`` after each cycle. Ctrl-C (or an
    exception in ``progress``) stops the run with a checkpoint and is raised; continue with
    ``resume=``. Returns a dict: settings, grains, cycles_done, particle_steps_per_second,
    written, checkpoint, report (the command line's summary)."""
    if out is not None:
        settings["out"] = os.fspath(out)
    return _granmem.simulate(settings, os.fspath(resume) if resume else "",
                             os.fspath(start_from) if start_from else "", int(threads),
                             progress)


def readout(states, out, amplitudes="0.05%:2.5%:12", cycles=1, drive="asymmetric",
            wall_motion="cosine", inertial_number=None, training_amplitude=True, parallel=0,
            bootstrap=200, progress=None):
    """The paper's memory read-out, as ``granmem readout``: one run of ``cycles`` cycles at
    each amplitude A' from each trained state (checkpoints, e.g. ``simulate(...,
    keep_states=[10, 100])``), ``parallel`` at once, stores in the folder ``out`` (finished
    runs are reused when called again).

    ``amplitudes``: "lo%:hi%:count" (log-spaced) or a list of percentages, e.g. [0.5, 1, 2].
    ``inertial_number``: the drive's quasi-static limit (None: granmem's default, as
    ``simulate``'s). Returns a dict: ``points`` (a DataFrame of the read-out curves: state, amplitude_pct,
    cycle, dr_d, msd_d2, rotations, their errors) and ``signatures`` (each state's memory:
    the dip at its training amplitude, the ratio to an untrained packing, the rotations'
    power laws). Ctrl-C stops after the runs under way and is raised."""
    if not isinstance(amplitudes, str):
        amplitudes = ",".join(f"{a}%" for a in amplitudes)
    if isinstance(states, (str, os.PathLike)):
        states = [states]
    out_dict = _granmem.readout([os.fspath(s) for s in states], os.fspath(out), amplitudes,
                                int(cycles), drive, wall_motion,
                                _granmem.QUASI_STATIC_INERTIAL_NUMBER
                                if inertial_number is None else float(inertial_number),
                                bool(training_amplitude), int(parallel), int(bootstrap),
                                progress)
    return {"points": _frame(*out_dict["points"], length_unit="d"),
            "signatures": _frame(*out_dict["signatures"]),
            "diameter": out_dict["diameter"], "table": out_dict["table"],
            "signature_table": out_dict["signature_table"]}


def compare(a, b, out, window=None, diameter=None, label_a="A", label_b="B", wall_distance=0,
            subtract_drift=True, steady_points=0):
    """Two runs side by side, as ``granmem compare`` (an experiment and a simulation, or two
    simulations): end-of-cycle displacement and rotation distributions over ``window``
    (``(first, last)`` cycles; default both runs' last 10 common cycles), their KS and
    Wasserstein-1 distances, and the paper's figures, written in the folder ``out``.
    Lengths in grain ``diameter`` ("5mm"; default twice a's median radius);
    ``wall_distance`` with a unit ("5mm") or in m.

    Returns a dict: ``distances`` (quantity -> ks, wasserstein1_d), ``written`` (files),
    ``notes`` and ``report`` (the command line's lines)."""
    return _granmem.compare(os.fspath(a), os.fspath(b), os.fspath(out), _range(window),
                            diameter, label_a, label_b, _length(wall_distance),
                            bool(subtract_drift), int(steady_points))


def _frictions(value):
    if value is None or isinstance(value, str):
        return value
    return ",".join(repr(float(m)) for m in value)


def _optional_float(value):
    return None if value is None else float(value)


def calibrate(experiment, out, mu_s=None, mu_r=None,
              observables="steady-state", only=(), window=None, noise="auto",
              summaries="pooled", wall_distance=0, subtract_drift=True, degree=0, replicas=None,
              refine=None, axis_noise="auto", deposit="auto", placed_jitter="auto",
              placed_cycle="auto", fit_only=False, one_cycle_ahead=None, ahead_burn_in=1,
              true_mu_s=None, true_mu_r=None, parallel=0, progress=None, **twin):
    """The friction fit, as ``granmem calibrate``: a simulated twin of the ``experiment``
    (a trajectory store, tracked scans or a pseudo-experiment) run at each friction of
    ``mu_s`` (and each ``mu_r`` for a joint fit of both) on ``replicas`` packings, in the
    folder ``out`` (finished runs are reused when called again), and the friction fitted
    with Ceres so that the twin's ``observables`` match the experiment's over ``window``
    (``(first, last)`` cycles; default its last 10; "auto" with steady-state: the longest
    window ending there over which the twin's runs are steady): "steady-state" (the default:
    window means of displacement, rotation, packing fraction, coordination, wall force, and for
    a twin placed before the frame before the window the packing's height there; ``only`` a
    subset) or "displacements" (the end-of-cycle displacement distribution). docs/CALIBRATION.md says which
    identify friction. ``refine`` (steady-state): that many packings more, each its own seed,
    about the fit of the ``mu_s`` (x ``mu_r``) x ``replicas`` design (placed: one at fit /
    1.15, one at fit x 1.15, the rest at it; poured: all at it), and the fit made again on
    every run (``None``: 0, but for a steady-state fit of mu_s whose ``mu_s`` and ``replicas``
    are left to it 3, placed 4; placed from scans after the drive began, the last is the
    placement probe, the first placed again from its own frame moved by the scans' error). ``axis_noise``
    (steady-state, degrees): the experiment's error in each hole axis (a scan's), added to
    the twin's exact axes before their rotations are measured;
    "auto": the scans' own RMS axis standard error where the store has them, else none.
    ``noise`` (displacements): "scans" takes the RMS of the scans' position standard errors
    ("auto" too where the store has them, else fits it on scans). ``deposit``: "each" (every
    run pours its own packing at its friction), "shared" (one per seed, its friction
    switched) or "experiment" (every run starts from the grains of the experiment's frame of
    cycle ``placed_cycle``, "auto": the one before the window, for scans their first frame
    where it holds the packing, and drives the cycles after it;
    each replica moved by ``placed_jitter``, a length; "auto": 1e-4 grain diameters) or "auto"
    (the default: "experiment" for a steady-state fit of mu_s on a simulation's packing,
    whose frame there holds it exactly, else "each"). ``one_cycle_ahead`` (steady-state, a
    placed twin, mu_s): after the design's fit, one packing more at fit / 1.2, / 1.07, x 1.07
    and x 1.2, placed anew from the experiment's frame of every cycle before one of the window
    and driven that one cycle; the fit the mean of the cycles' own, its error their scatter
    (no refined packings, no comparison run; docs/CALIBRATION.md, "One cycle ahead");
    ``None``: on where the experiment has the frames of 5 or more of the window's cycles, and
    ``refine``, ``placed_cycle`` and an "auto" ``window`` are not given (the default);
    ``False``: the window's means. ``ahead_burn_in``: the cycles each of its runs drives
    before the one compared, placed from the frame that many cycles earlier (1: the placed
    contacts' tangential history loaded again by a cycle; each compared cycle needs its
    frame and those ``ahead_burn_in`` + 1 before it).

    ``mu_s`` and ``replicas`` left ``None``: the design measured for each fit, for
    "steady-state" 0.05, 0.14, 0.4 on 3 packings, then 3 more at their fit (12 runs; a twin
    placed from the experiment's packing 0.05, 0.13, 0.35, 0.6 on 2, then 4 more at their fit), for the
    joint fit 0.05, 0.12, 0.3 on 2 (x each ``mu_r``), for "displacements" 0.03, 0.05, 0.08,
    0.12, 0.2, 0.3, 0.5 on 2. ``degree``: of the trend in ln mu_s through the runs; 0: 3 for
    mu_s alone on a twin placed from the experiment's packing, else 2.

    ``twin``: the twin's simulate settings with ``_`` for ``-``, e.g. ``grains=1500,
    box="5cm", amplitude="1%"`` (as ``simulate``; the experiment's protocol). ``progress``
    gets dicts with a ``line`` (and a run's ``cycle``, ``cycles``, ...). Ctrl-C stops
    after the runs under way and is raised. Returns a dict: mu_s, mu_s_ci95 (and mu_r,
    mu_r_ci95, correlation for a joint fit), true_mu_s / true_mu_r (a pseudo-experiment's,
    else NaN; ``true_mu_s``, ``true_mu_r``: a pseudo-experiment's whose store does not say
    them, scans drawn from a simulation, for the report and the figures), simulations
    (the one more at the fit for the comparison included), simulations_fitted,
    notes, written, report (the command line's lines)."""
    only = [only] if isinstance(only, str) else list(only)
    return _granmem.calibrate(os.fspath(experiment), os.fspath(out), _frictions(mu_s),
                              _frictions(mu_r), observables, only, _range(window), str(noise),
                              summaries, _length(wall_distance), bool(subtract_drift),
                              int(degree), None if replicas is None else int(replicas),
                              None if refine is None else int(refine),
                              "auto" if axis_noise is None else axis_noise if isinstance(
                                  axis_noise, str) else repr(float(axis_noise)),
                              deposit, "auto" if placed_jitter == "auto" else _length(placed_jitter),
                              "auto" if placed_cycle is None else str(placed_cycle), bool(fit_only),
                              None if one_cycle_ahead is None else bool(one_cycle_ahead),
                              int(ahead_burn_in),
                              _optional_float(true_mu_s),
                              _optional_float(true_mu_r), int(parallel), twin, progress)
