"""Tracked scans against the DEM run they were rendered from (a pseudo-experiment): each
scan's position error, the error of each end-of-cycle displacement, how much the errors of
consecutive scans share, what locate's stored standard errors predict, and the part of the
errors touching neighbours do not share (what calibrate reads from the contacts' spread),
and what the errors share where the packing is one-sided: the mean error of the grains in
the layers at the floor, the top and the side walls (a diameter deep), and how much shorter
or longer the scans read the distances of near pairs (docs/CALIBRATION.md, "The scans'
locating noise given to the twin").
Usage: scripts/scan_errors_against_truth.py TRACKS.h5 DEM.h5   (PYTHONPATH=build/python)"""
import sys
import numpy as np
from scipy.spatial import cKDTree
import granmem

trk, dem = granmem.read_run(sys.argv[1]), granmem.read_run(sys.argv[2])
d = 2 * np.nanmedian(dem["radius"])
vox = np.asarray(trk["voxel_size"])
steps = list(trk["step"])
def frame(run, step): return run["position"][list(run["step"]).index(step)]
t0 = frame(trk, steps[0])
seen = np.all(np.isfinite(t0), axis=1)
dist, idx = cKDTree(frame(dem, steps[0])).query(np.where(seen[:, None], t0, 1e9))
ok = seen & (dist < 0.2 * d)
def errors(s):  # each tracked grain's position less its DEM grain's, common offset removed
    e = frame(trk, s) - frame(dem, s)[idx]
    m = ok & np.all(np.isfinite(e), 1)
    return e - np.median(e[m], 0), m
pos, disp, pred, corr, apart, along, cos_z = [], [], [], [], [], [], []
sigma = lambda s: trk["position_error"][steps.index(s)] / vox
for a, b in zip(steps[:-1], steps[1:]):
    ea, ma = errors(a)
    eb, mb = errors(b)
    m = ma & mb
    disp.append((eb - ea)[m] / vox)
    pred.append(np.sqrt(sigma(a)[m] ** 2 + sigma(b)[m] ** 2))
    corr.append([np.corrcoef(ea[m, k], eb[m, k])[0, 1] for k in range(3)])
for s in steps:
    e, m = errors(s)
    pos.append(e[m] / vox)
    # touching neighbours (DEM centres within 1.0 d): their errors' difference / sqrt 2
    x = frame(dem, s)[idx]
    pairs = cKDTree(x[m]).query_pairs(d, output_type="ndarray")
    diff = (e[m][pairs[:, 1]] - e[m][pairs[:, 0]]) / np.sqrt(2)
    u = x[m][pairs[:, 1]] - x[m][pairs[:, 0]]
    u /= np.linalg.norm(u, axis=1)[:, None]
    apart.append(diff / vox)
    along.append(np.sum(diff * u, 1))
    cos_z.append(np.abs(u[:, 2]))
rms = lambda x: np.sqrt(np.mean(np.vstack(x) ** 2, 0))
print(f"{sys.argv[1]}: {ok.sum()} grains matched, scans {steps[0]}-{steps[-1]}; voxels, x y z")
print("position error RMS              ", rms(pos).round(4))
print("|position error| median, 99th %", [np.quantile(np.abs(np.vstack(pos)), q, 0).round(4)
                                         for q in (0.5, 0.99)])
print("its standard error RMS          ", rms([sigma(s)[ok] for s in steps]).round(4))
print("displacement error RMS          ", rms(disp).round(4))
print("predicted, sqrt(s_a^2 + s_b^2)  ", rms(pred).round(4))
print("consecutive scans' errors, corr.", np.mean(corr, 0).round(3))
print("touching neighbours' difference / sqrt 2, RMS", rms(apart).round(4),
      "=", (rms(apart) * vox * 1e6).round(2), "um")
# along the contact: variance = across^2 (1 - u_z^2) + along_z^2 u_z^2, least squares
a, uz = np.concatenate(along), np.concatenate(cos_z)
split = np.linalg.lstsq(np.c_[1 - uz**2, uz**2], a**2, rcond=None)[0]
print("the same along the contact, across and along z, um", (np.sqrt(split) * 1e6).round(2),
      "; a contact's mean error", round(np.mean(a) * np.sqrt(2) * 1e6, 2), "um")

# One-sided grains: the layer a diameter deep at each end, its mean error (inward +).
layer = {k: [] for k in ("bottom", "top", "x low", "x high", "y low", "y high")}
gaps = [(0.99, 1.0005), (1.0005, 1.005), (1.005, 1.02)]
short = [[] for _ in gaps]
pull, towards = [], []  # each error, and the sum of the unit vectors to its touching neighbours
for s in steps:  # each scan matched to its DEM frame anew: linking's mistakes left out
    y = frame(trk, s)
    y = y[np.all(np.isfinite(y), 1)]
    near, i = cKDTree(frame(dem, s)).query(y)
    x = frame(dem, s)[i[near < 0.2 * d]]
    e = y[near < 0.2 * d] - x
    e -= np.median(e, 0)
    for axis, low, high in ((2, "bottom", "top"), (0, "x low", "x high"), (1, "y low", "y high")):
        lo, hi = x[:, axis].min(), x[:, axis].max()
        layer[low].append(e[x[:, axis] - lo < d, axis])
        layer[high].append(-e[hi - x[:, axis] < d, axis])
    pairs = cKDTree(x).query_pairs(1.02 * d, output_type="ndarray")
    true = np.linalg.norm(x[pairs[:, 1]] - x[pairs[:, 0]], axis=1)
    scanned = np.linalg.norm((x + e)[pairs[:, 1]] - (x + e)[pairs[:, 0]], axis=1)
    for k, (lo, hi) in enumerate(gaps):
        g = (true >= lo * d) & (true < hi * d)
        short[k].append(scanned[g] - true[g])
    touching = pairs[true < 1.001 * d]
    u = x[touching[:, 1]] - x[touching[:, 0]]
    u /= np.linalg.norm(u, axis=1)[:, None]
    f = np.zeros_like(x)
    np.add.at(f, touching[:, 0], u)
    np.add.at(f, touching[:, 1], -u)
    pull.append(e)
    towards.append(f)
print("end layers' mean error, inward, um:",
      ", ".join(f"{k} {np.mean(np.concatenate(v)) * 1e6:+.2f}" for k, v in layer.items()))
print("near pairs, scanned less true distance, um:",
      ", ".join(f"{lo}-{hi} d {np.mean(np.concatenate(v)) * 1e6:+.2f} ({sum(map(len, v))})"
                for (lo, hi), v in zip(gaps, short)))
# The error's part along the sum of unit vectors to the touching neighbours (within 1.001 d):
# a centre pulled towards them by c per neighbour's direction, per axis.
e, f = np.vstack(pull), np.vstack(towards)
c = np.sum(f * e, 0) / np.sum(f * f, 0)
print("pulled towards touching neighbours, um per unit vector (x y z):", (c * 1e6).round(2),
      "; correlation", np.round([np.corrcoef(f[:, k], e[:, k])[0, 1] for k in range(3)], 3),
      "; error RMS", (e.std(0) * 1e6).round(2), "-> without it", ((e - f * c).std(0) * 1e6).round(2))
