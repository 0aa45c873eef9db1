#!/usr/bin/env bash
# The main job on the sample data: install what is needed, build, then the whole pipeline.
#  1. the sample table of tracked grains imported and analysed;
#  2. a pseudo-experiment: the DEM at a known sliding friction (TRUE_MU_S below), its state
#     at the end of each cycle drawn as laser-sheet scans (granmem render);
#  3. the scans tracked (locate, link) and analysed: displacements, single-axis rotations;
#  4. granmem calibrate: the DEM's friction fitted to the tracked scans, with its interval,
#     distances and figures;
#  5. the fitted friction printed next to the true one.
# Output in out/sample/. Settings in sample_data/sample.toml.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
granmem=build/app/granmem
config=sample_data/sample.toml
out=out/sample
TRUE_MU_S=0.15
rm -rf "$out/scans" "$out/calibration"
mkdir -p "$out/scans"
SECONDS=0
step() { echo "== [${SECONDS} s] $*" >&2; }

step "1/5 the sample table of tracked grains"
"$granmem" --config $config import sample_data/tracked_grains.csv --out "$out/run.h5"
"$granmem" --config $config analyze "$out/run.h5" --out "$out/analysis"

step "2/5 pseudo-experiment: DEM at mu_s = $TRUE_MU_S (seed 101), scans of each cycle's end"
"$granmem" --config $config simulate --mu-s $TRUE_MU_S --seed 101 --threads 2 \
  --out "$out/experiment_dem.h5"
render() {  # one scan of the end of cycle $1
  "$granmem" --config $config render "$out/experiment_dem.h5" --frame "$1" --seed $(($1 + 1)) \
    --out "$out/scans/scan$1.tif" --truth "$out/scans/truth$1.csv" > "$out/scans/render$1.log"
}
for pair in "0 1" "2 3"; do  # two at a time, one per core
  pids=()
  for cycle in $pair; do render "$cycle" & pids+=($!); done
  for pid in "${pids[@]}"; do wait "$pid"; done
done

step "3/5 tracking the scans (locate, link) and analysing the tracks"
"$granmem" track "$out"/scans/scan*.tif --diameter 5mm --container-size 5,5,15cm \
  --out "$out/tracks.h5" \
  --analyze "$out/tracks_analysis"

step "4/5 calibrating the DEM's friction on the tracked scans"
"$granmem" --config $config calibrate --experiment "$out/tracks.h5" --out "$out/calibration" \
  --true-mu-s $TRUE_MU_S | tee "$out/calibration.txt"

step "5/5 result"
summary="$out/calibration/summary.json"
fitted=$(sed -n 's/^  "mu_s": \(.*\),$/\1/p' "$summary" | xargs printf '%.3g')
interval=$(sed -n 's/^  "mu_s_ci95": \[\(.*\),\(.*\)\],$/\1 \2/p' "$summary" |
  xargs printf '%.3g-%.3g')
echo "sliding friction: fitted $fitted (95% interval $interval), true $TRUE_MU_S" \
  | tee "$out/result.txt"
echo "figures and tables in $out/calibration/ (observable_fit.png, pdf_displacement.png, ...)"
step "done"
