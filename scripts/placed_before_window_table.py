#!/usr/bin/python3
"""docs/data/friction/placed_before_window.csv (docs/CALIBRATION.md, "The placed twin started
before the window"): the placed twin started before the window against session 21-25's placed at
cycle 0, on the same blind DEM pseudo-experiments. Writes the CSV to stdout.
Usage: scripts/placed_before_window_table.py FITS  (FITS/fit_<mu>_s<seed>/summary.json)"""
import csv, json, os, sys
FITS = sys.argv[1] if len(sys.argv) > 1 else 'out/s26'
D = 'docs/data/friction/'
def rows(name):
    return list(csv.DictReader(l for l in open(D + name) if not l.startswith('#')))
before = {}
for r in rows('placed_twin_staged_design.csv'):
    mu, seed = r['experiment'].split('_seed_')
    before[(mu, seed)] = ('2500 grains x 30 cycles, window 21:30', r['staged_mu_s'], r['staged_ci95_low'], r['staged_ci95_high'])
for f, proto in [('blind_1500_12cycles.csv', '1500 grains x 12 cycles, window 3:12'),
                 ('blind_3000_20cycles.csv', '3000 grains x 20 cycles, window 11:20')]:
    for r in rows(f):
        before[(r['mu_s_true'], r['seed'])] = (proto, r['mu_s'], r['ci95_low'], r['ci95_high'])
out = csv.writer(sys.stdout, lineterminator='\n')
print('# Session 26: blind DEM pseudo-experiments fitted by calibrate\'s placed staged default (2 x 0.05, 0.13, 0.35, 0.6,')
print('# then 4 packings at that fit, 12 runs), the twin placed from the experiment\'s frame of cycle 0 (sessions 21-25)')
print('# and from its frame before the window (session 26: the runs drive only the window); docs/CALIBRATION.md')
print('# "The placed twin started before the window"')
out.writerow(['protocol', 'mu_s_true', 'seed', 'cycle0_mu_s', 'cycle0_ci95_low', 'cycle0_ci95_high', 'cycle0_width',
              'cycle0_bar', 'before_window_mu_s', 'before_window_ci95_low', 'before_window_ci95_high',
              'before_window_width', 'before_window_error', 'before_window_holds', 'before_window_bar',
              'chi2', 'dof', 'n_simulations'])
def bar(t, m, lo, hi):
    return 'yes' if abs(m - t) <= 0.02 and lo <= t <= hi and hi - lo <= 0.08 else 'no'
for (mu, seed), (proto, m0, lo0, hi0) in sorted(before.items(), key=lambda kv: (kv[1][0], float(kv[0][0]))):
    name = f'{FITS}/fit_{mu}_s{seed}/summary.json'
    if not os.path.exists(name): continue
    j = json.load(open(name)); t = float(mu)
    m, (lo, hi) = j['mu_s'], j['mu_s_ci95']
    m0, lo0, hi0 = float(m0), float(lo0), float(hi0)
    out.writerow([proto, mu, seed, f'{m0:.4g}', f'{lo0:.4g}', f'{hi0:.4g}', f'{hi0-lo0:.3f}', bar(t, m0, lo0, hi0),
                  f'{m:.4g}', f'{lo:.4g}', f'{hi:.4g}', f'{hi-lo:.3f}', f'{m-t:+.4f}',
                  'yes' if lo <= t <= hi else 'no', bar(t, m, lo, hi), f'{j["chi2"]:.2f}', int(j['dof']),
                  j['n_simulations']])
