#!/usr/bin/env bash
# A pseudo-experiment's scans drawn, tracked and fitted (docs/CALIBRATION.md, issue 17:
# "also from rendered and tracked scans of such a run"): the scan of cycle 0 (where a
# placed twin takes its grains) and of each cycle from one before the window to its end,
# default render (12 pixels a grain, each scan its own noise seed), each scan located
# apart and the detections linked across the gap; then the steady-state fit twice, the
# twin placed where the scans have the grains before the window (cycle 0 until session 26;
# the placed default design; fine scans' default since session 27) and poured (--deposit
# each, the scans' default before).
#
#   scripts/tracked_twin_study.sh PSEUDO.h5 PROTOCOL.toml FIRST:LAST OUT [GRANMEM]
#
# PROTOCOL.toml: the pseudo-experiment's [simulate] and the window as [calibrate] window;
# FIRST:LAST the window. Grains of 5 mm in a 5 x 5 cm box (the scans' container, 15 cm
# tall to hold the packing). Writes OUT/tracks.h5, OUT/placed.txt, OUT/poured.txt and the
# fits' folders; a second call reuses what the first finished (granmem writes each file
# whole or not at all).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 4 ] || { sed -n 2,16p "$0"; exit 2; }
pseudo=$(realpath "$1") protocol=$(realpath "$2") window=$3 out=$4
granmem=$(realpath "${5:-$root/build/app/granmem}")
first=${window%:*} last=${window#*:}
mkdir -p "$out/det" && cd "$out"

frames=$( { echo 0; seq $((first > 1 ? first - 1 : 1)) "$last"; } | sort -nu)
for f in $frames; do
  [ -f "scan$f.tif" ] || "$granmem" render "$pseudo" --frame "$f" --seed $((f + 5)) \
    --out "scan$f.tif" > /dev/null
  [ -f "det/scan$f.h5" ] || "$granmem" track "scan$f.tif" --diameter 5mm --first-cycle "$f" \
    --detections det --out "det/track$f.h5" > "det/track$f.txt" 2>&1
done
[ -f tracks.h5 ] || "$granmem" link $(for f in $frames; do echo "det/scan$f.h5"; done) \
  --container-size 5,5,15cm --out tracks.h5 > link.txt 2>&1
for twin in placed poured; do
  deposit=$([ $twin = placed ] && echo experiment || echo each)
  [ -f "$twin/summary.json" ] || "$granmem" --config "$protocol" calibrate \
    --experiment tracks.h5 --out "$twin" --observables steady-state --deposit "$deposit" \
    > "$twin.txt" 2> "$twin.log"
done
grep -h 'mu_s = ' placed.txt poured.txt
