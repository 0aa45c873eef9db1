#!/usr/bin/env python3
"""One CSV line per calibrate fit (its summary.json): the fitted mu_s, its 95 % interval and
width, the error against the true mu_s, whether the interval holds it and whether issue 17's
bar is met (within +-0.02 and no wider than 0.08), and the experiment's systematic errors' share
of the fit's error in ln mu_s (since session 31; empty before).
Usage: scripts/calibrate_fits_table.py LABEL=FIT_DIR ...   (LABEL: any text, e.g. scans_s43_deg3)"""
import json
import sys

print("label,true_mu_s,mu_s,ci95_low,ci95_high,width,error,interval_holds,bar_met,chi2,dof,"
      "simulations,systematic_sigma")
for arg in sys.argv[1:]:
    label, folder = arg.split("=", 1)
    s = json.load(open(folder + "/summary.json"))
    mu, (lo, hi), true = s["mu_s"], s["mu_s_ci95"], s.get("mu_s_true")
    holds = true is not None and lo <= true <= hi
    bar = holds and abs(mu - true) <= 0.02 and hi - lo <= 0.08
    print(f"{label},{true},{mu:.4g},{lo:.4g},{hi:.4g},{hi - lo:.3g},{mu - true:+.4f},"
          f"{'yes' if holds else 'no'},{'yes' if bar else 'no'},{s['chi2']:.3g},{s['dof']},"
          f"{s['n_simulations']},{format(s['systematic_sigma'], '.3g') if 'systematic_sigma' in s else ''}")
