"""Tracked scans' hole axes against the DEM run they were drawn from (a pseudo-experiment):
each scan's actual axis error (the angle to the matched DEM grain's body z axis, matched by
position in each frame) against locate's stored axis standard error, and the mean
single-axis rotation between consecutive scans as scanned, as simulated, and as simulated
with the twin's axis noise (a tilt of the stored RMS standard error in each direction across
the axis, as calibrate gives its twin's axes).
Usage: /usr/bin/python3 scripts/scan_axis_errors_against_truth.py TRACKS.h5 DEM.h5"""
import sys
import h5py
import numpy as np
from scipy.spatial import cKDTree

SCALE = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6}


def load(path):
    with h5py.File(path, "r") as f:
        g = f["/particles/grains"]
        unit = g["position/value"].attrs.get("unit", b"m")
        unit = unit.decode() if isinstance(unit, bytes) else unit
        run = {"pos": g["position/value"][...] * SCALE[unit],
               "step": list(g["position/step"][...])}
        for key, name in (("axis", "axis"), ("q", "orientation"), ("axis_error", "axis_error")):
            if name in g:
                run[key] = g[name + "/value"][...]
    return run


def body_z(q):  # quaternion (w, x, y, z) turning e_z
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)], -1)


def angle(a, b):  # degrees between unsigned axes
    c = np.abs(np.sum(a * b, -1)) / np.linalg.norm(a, axis=-1) / np.linalg.norm(b, axis=-1)
    return np.degrees(np.arccos(np.clip(c, 0, 1)))


def tilted(a, sigma_deg, rng):
    a = a / np.linalg.norm(a, axis=1)[:, None]
    u = np.cross(a, [1.0, 0, 0])
    u /= np.linalg.norm(u, axis=1)[:, None]
    v = np.cross(a, u)
    s = np.radians(sigma_deg)
    return a + s * (rng.normal(size=(len(a), 1)) * u + rng.normal(size=(len(a), 1)) * v)


trk, dem = load(sys.argv[1]), load(sys.argv[2])
frame = lambda run, key, s: run[key][run["step"].index(s)]
steps = trk["step"]
match, stored = {}, []
for s in steps:
    t = frame(trk, "pos", s)
    seen = np.all(np.isfinite(t), 1)
    dist, idx = cKDTree(frame(dem, "pos", s)).query(np.where(seen[:, None], t, 1e9))
    ok = seen & (dist < 1e-3) & np.all(np.isfinite(frame(trk, "axis", s)), 1)
    match[s] = (idx, ok)
    e = angle(frame(trk, "axis", s)[ok], body_z(frame(dem, "q", s))[idx[ok]])
    se = np.degrees(np.sqrt(np.nanmean(frame(trk, "axis_error", s)[ok] ** 2)))
    stored.append(se)
    # an isotropic tilt of sigma in each of two directions: the angle's RMS is sqrt(2) sigma
    print(f"cycle {s}: {ok.sum()} grains, axis error {np.sqrt(np.mean(e ** 2) / 2):.3f} deg a "
          f"direction (99th percentile of the angle {np.percentile(e, 99):.2f}); stored "
          f"standard error {se:.3f}")
rng = np.random.default_rng(1)
sigma = float(np.sqrt(np.mean(np.square(stored))))
scanned, true, modelled = [], [], []
for s0, s1 in zip(steps[:-1], steps[1:]):
    if s1 != s0 + 1:
        continue
    (i0, o0), (i1, o1) = match[s0], match[s1]
    m = o0 & o1 & (i0 == i1)
    t0, t1 = body_z(frame(dem, "q", s0))[i0[m]], body_z(frame(dem, "q", s1))[i1[m]]
    scanned.append(angle(frame(trk, "axis", s0)[m], frame(trk, "axis", s1)[m]).mean())
    true.append(angle(t0, t1).mean())
    modelled.append(angle(tilted(t0, sigma, rng), tilted(t1, sigma, rng)).mean())
print(f"mean rotation a cycle over {len(scanned)} pairs of scans: scanned {np.mean(scanned):.4f} "
      f"deg, simulated {np.mean(true):.4f}, simulated with {sigma:.3f} deg of axis noise "
      f"{np.mean(modelled):.4f}")
