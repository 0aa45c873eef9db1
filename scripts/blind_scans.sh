#!/usr/bin/env bash
# Blind pseudo-experiments fitted from their tracked scans (docs/CALIBRATION.md, "The wall's
# force read beside the scans"): for each MU:SEED a pseudo-experiment of PROTOCOL.toml's
# [simulate] (its [calibrate] window FIRST:LAST), its frames 0 and FIRST-1..LAST drawn with
# the default render and tracked, then calibrate with the defaults (a placed twin for fine
# scans), and again with the DEM's wall force read beside the scans (--readings; the twin's
# runs reused). Prints one line per case and writes OUT/blind_scans.csv.
#
#   [RENDER="--diameter-px 16 ..."] scripts/blind_scans.sh OUT PROTOCOL.toml MU:SEED [MU:SEED ...]
#
# RENDER: `granmem render` options for another scanner than the default render. A second
# call reuses what the first finished (each file is written whole or not at all), a
# pseudo-experiment already in OUT/sSEED/pseudo.h5 too.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 3 ] || { sed -n 2,13p "$0"; exit 2; }
read -r -a render <<< "${RENDER:-}"
out=$(realpath -m "$1") protocol=$(realpath "$2")
shift 2
granmem=${GRANMEM:-$root/build/app/granmem}
window=$(sed -n 's/^window *= *"\(.*\)".*/\1/p' "$protocol")
first=${window%:*} last=${window#*:}
frames="0 $(seq $((first > 1 ? first - 1 : 1)) "$last")"
mkdir -p "$out"
for case in "$@"; do
  mu=${case%%:*} seed=${case#*:}
  d=$out/s$seed
  mkdir -p "$d/det" && cd "$d"
  [ -f pseudo.h5 ] || "$granmem" --config "$protocol" simulate --mu-s "$mu" --seed "$seed" \
    --threads 2 --out pseudo.h5 > sim.log 2>&1
  for f in $frames; do
    [ -f "scan$f.tif" ] || "$granmem" render pseudo.h5 --frame "$f" --seed $((f + 5)) \
      "${render[@]}" --out "scan$f.tif" > /dev/null
    [ -f "det/scan$f.h5" ] || "$granmem" track "scan$f.tif" --diameter 5mm --first-cycle "$f" \
      --detections det --out "det/track$f.h5" > "det/track$f.txt" 2>&1
  done
  /usr/bin/python3 "$root/scripts/apparatus_readings_of_run.py" pseudo.h5 > readings.csv
  scans=$(for f in $frames; do echo "det/scan$f.h5"; done)
  [ -f tracks.h5 ] || "$granmem" link $scans --container-size 5,5,15cm --out tracks.h5 > link.txt
  [ -f tracks_readings.h5 ] || "$granmem" link $scans --container-size 5,5,15cm \
    --readings readings.csv --out tracks_readings.h5 > link_readings.txt 2>&1
  [ -f fit/summary.json ] || "$granmem" --config "$protocol" calibrate --experiment tracks.h5 \
    --out fit --fit-only --true-mu-s "$mu" > fit.log 2>&1
  # the twin's runs reused: the design's, and one cycle ahead's where their frictions agree
  mkdir -p fit_readings && ln -sfn ../fit/runs fit_readings/runs && ln -sfn ../fit/ahead fit_readings/ahead
  [ -f fit_readings/summary.json ] || "$granmem" --config "$protocol" calibrate \
    --experiment tracks_readings.h5 --out fit_readings --fit-only --true-mu-s "$mu" \
    > fit_readings.log 2>&1
  echo "$mu s$seed: $(grep -h '^mu_s =' fit.log) | with the wall's force: $(grep -h '^mu_s =' fit_readings.log)"
done
cd "$out"
/usr/bin/python3 - "$@" <<'PY'
import json, sys
rows = ["true_mu_s,seed,wall_force_read,mu_s,ci95_low,ci95_high,width,error,chi2,dof,n_simulations"]
for case in sys.argv[1:]:
    seed = case.split(":")[1]
    for fit, force in (("fit", 0), ("fit_readings", 1)):
        s = json.load(open(f"s{seed}/{fit}/summary.json"))
        lo, hi = s["mu_s_ci95"]
        t = s["mu_s_true"]
        rows.append(f"{t},{seed},{force},{s['mu_s']:.4g},{lo:.4g},{hi:.4g},{hi - lo:.3g},"
                    f"{s['mu_s'] - t:+.4f},{s['chi2']:.3g},{s['dof']:g},{s['n_simulations']}")
open("blind_scans.csv", "w").write("\n".join(rows) + "\n")
PY
echo "wrote $out/blind_scans.csv"
