#!/usr/bin/env bash
# What a placed twin loses with its contact history (docs/CALIBRATION.md, "The contact history
# a placed twin loses"): a pseudo-experiment of PROTOCOL.toml at MU (seed SEED) kept whole at
# the frame before its window; that state continued through the window four times, its grains
# moved by 1 nm (history kept: kept1-4.h5) and by 0.5 um (kicked1-4.h5); the twin placed from
# the same frame at MU and 7 % above, four packings each (placed/); with TRACKS.h5 (the run's
# scans tracked) the twin placed from them too (scanplaced/). Resumes: what exists is kept.
# ~10 min a 2,500-grain case on 2 cores.
# Usage: scripts/history_kept_or_lost.sh PROTOCOL.toml OUT MU:SEED [TRACKS.h5]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
granmem=${GRANMEM:-$root/build/app/granmem}
protocol=$(realpath "$1") out=$2 mu=${3%%:*} seed=${3#*:} tracks=${4:+$(realpath "$4")}
window=$(sed -n 's/^window *= *"\(.*\)".*/\1/p' "$protocol")
first=${window%:*} last=${window#*:}
placed=$((first - 1)) n=$((last - first + 1))
hi=$(awk -v m="$mu" 'BEGIN { printf "%.4g", 1.07 * m }')
mkdir -p "$out" && cd "$out"
[ -f truth.h5 ] || "$granmem" --config "$protocol" simulate --mu-s "$mu" --seed "$seed" \
  --threads 2 --keep-states "$placed" --out truth.h5 > truth.log 2>&1
for j in 1 2 3 4; do
  for kind in kept:1e-9 kicked:0.5e-6; do
    name=${kind%%:*}$j
    [ -f "$name.h5" ] && continue
    /usr/bin/python3 "$root/scripts/move_state.py" "truth_state_cycle$placed.h5" "$name.state.h5" "$j" "${kind#*:}"
    "$granmem" --config "$protocol" simulate --start-from "$name.state.h5" --cycles "$n" \
      --threads 2 --out "$name.h5" > "$name.log" 2>&1
  done
done
twin() {  # twin DIR EXPERIMENT
  [ -f "$1/summary.json" ] || "$granmem" --config "$protocol" calibrate --experiment "$2" --out "$1" \
    --fit-only --mu-s "$mu,$hi" --replicas 4 --refine 0 --degree 1 --true-mu-s "$mu" > "$1.log" 2>&1
}
twin placed truth.h5
[ -z "$tracks" ] || twin scanplaced "$tracks"
PYTHONPATH="$root/build/python${PYTHONPATH:+:$PYTHONPATH}" /usr/bin/python3 "$root/scripts/history_kept_or_lost.py" . "$mu" "$first:$last"
