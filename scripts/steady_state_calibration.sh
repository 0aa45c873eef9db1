#!/usr/bin/env bash
# The steady-state friction fit measured on pseudo-experiments (docs/CALIBRATION.md, issue
# 17): pseudo-experiments simulated by granmem at frictions the fit is not told, then
# `granmem calibrate --observables steady-state`, with one poured twin shared by all of them
# or (--deposit experiment) each one's own placed twin.
# Reduced scale at the paper's lid pressure: 1,500 grains of 5 mm, 5 cm box, 436 Pa,
# A = 1 %, 40 cycles, window 31:40 (the last 10, as the paper).
#
#   scripts/steady_state_calibration.sh [--out DIR] [--granmem BIN] [--mu-s LIST]
#                                       [--replicas N] [--joint] [--grains N]
#                                       [--cycles C] [--window F:L] [--pseudo LIST]
#                                       [--refine N] [--only LIST]
#                                       [--deposit each|experiment] [--inertial-number I]
#
# --grains, --cycles and --window change the protocol (default 1500, 40, 31:40); --pseudo
# the pseudo-experiments, as "mu_s:seed,mu_s:seed,..." (default 0.15:7,0.25:8,0.35:9,0.1:10).
#
# Pseudo-experiments (mu_s, seed): (0.15, 7), (0.25, 8), (0.35, 9), (0.1, 10). The twin:
# --mu-s (default 0.05,0.1,0.2,0.4) x --replicas packings (default 3: seeds 1-3) = 12
# runs, in DIR/runs, reused by every fit and by a second call (stopped runs are redone).
# --joint: also the joint mu_s / mu_r fit of the first pseudo-experiment (mu_r = 0.01) on
# a 3 x 3 grid (mu_s 0.05,0.12,0.3 x mu_r 0.004,0.012,0.036) x 2 packings, in DIR/joint.
# --refine N: the two-stage twin, N packings of new seeds added at the --mu-s x --replicas
# design's fit (`calibrate --refine`); its fits in DIR/fit_refineN_<pseudo>, DIR/fits_refineN.csv.
# --only: the observables fitted (default all the pseudo-experiment has).
# --deposit: each (default) pours the twin, one shared by all the pseudo-experiments, as
# the studies before 2026-11-26 were measured; experiment places each one's own twin from
# its packing (runs in DIR/runs_<pseudo>, shared by that pseudo-experiment's fits), with
# calibrate's placed default (staged) unless --mu-s, --replicas or --refine is given (its
# fits in DIR/fit_placed_default_<pseudo>, DIR/fits_placed_default.csv).
# --inertial-number: the drive (default 1e-3, as the studies before 2026-11-26; "default"
# leaves granmem's own).
# Writes DIR/fits.csv (one line per pseudo-experiment) and each fit's folder.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/out/steady_state_calibration"
granmem="$root/build/app/granmem"
mus="0.05,0.1,0.2,0.4"
replicas=3
design_given=0
deposit=each
inertial=1e-3
joint=0
grains=1500
cycles=40
window=31:40
pseudos="0.15:7,0.25:8,0.35:9,0.1:10"
refine=""
only=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out="$2"; shift ;;
    --granmem) granmem="$2"; shift ;;
    --mu-s) mus="$2"; design_given=1; shift ;;
    --replicas) replicas="$2"; design_given=1; shift ;;
    --deposit) deposit="$2"; shift ;;
    --inertial-number) inertial="$2"; shift ;;
    --joint) joint=1 ;;
    --grains) grains="$2"; shift ;;
    --cycles) cycles="$2"; shift ;;
    --window) window="$2"; shift ;;
    --pseudo) pseudos="$2"; shift ;;
    --refine) refine="$2"; shift ;;
    --only) only=(--only "$2"); shift ;;
    -h|--help) sed -n '2,33p' "$0"; exit 0 ;;
    *) echo "steady_state_calibration.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
case "$deposit" in
  each | experiment) ;;
  *) echo "steady_state_calibration.sh: --deposit is each or experiment, not $deposit" >&2; exit 2 ;;
esac
design=(--mu-s "$mus" --replicas "$replicas")
[[ $deposit == experiment && $design_given -eq 0 ]] && design=()
granmem=$(realpath "$granmem")
[[ -x $granmem ]] || { echo "steady_state_calibration.sh: no granmem at $granmem" >&2; exit 1; }
mkdir -p "$out/runs"
cd "$out"
cat > protocol.toml <<EOF
# $grains grains at the paper's lid pressure (the default 436 Pa), A = 1 %, $cycles cycles
[simulate]
grains = "$grains"
box = "5cm"
amplitude = "1%"
cycles = "$cycles"
$([[ $inertial == default ]] || echo "inertial-number = \"$inertial\"   # the drive")
[calibrate]
window = "$window"
EOF

pseudo() {  # name mu_s seed: simulated once, resumed from its checkpoint if stopped
  local name=$1 mu=$2 seed=$3
  [[ -e $name.done ]] && return 0
  local args=(--mu-s "$mu" --seed "$seed" --checkpoint-every 5 --out "$name.h5"
              --checkpoint "$name.checkpoint.h5")
  [[ -s $name.checkpoint.h5 ]] && args=(--resume "$name.checkpoint.h5")
  OMP_NUM_THREADS=1 "$granmem" --config protocol.toml simulate --threads 1 "${args[@]}" \
    > "$name.log" 2>&1 && touch "$name.done"
}
export -f pseudo
export granmem
names=()
for p in ${pseudos//,/ }; do names+=("pseudo_${p%%:*}_seed_${p##*:}"); done
for p in ${pseudos//,/ }; do echo "pseudo_${p%%:*}_seed_${p##*:} ${p%%:*} ${p##*:}"; done |
  xargs -P 2 -L 1 bash -c 'pseudo "$@"' _

tag=""
refine_args=()
[[ -n $refine ]] && refine_args=(--refine "$refine")
[[ ${refine:-0} -gt 0 ]] && tag="_refine$refine"
[[ -z $refine && ${#design[@]} -eq 0 ]] && tag="_placed_default"
echo "experiment,mu_s_true,mu_s,ci95_low,ci95_high,n_simulations" > "fits$tag.csv.tmp"
for p in "${names[@]}"; do
  fit="fit${tag}_$p"
  runs=runs
  [[ $deposit == experiment ]] && runs="runs_$p"
  mkdir -p "$fit" "$runs"
  ln -sfn "../$runs" "$fit/runs"
  "$granmem" --config protocol.toml calibrate --experiment "$p.h5" --out "$fit" \
    "${design[@]}" "${refine_args[@]}" "${only[@]}" --deposit "$deposit" \
    --observables steady-state --fit-only --threads 2 2> "$fit.log" | tee "$fit.txt"
  awk -v p="$p" '/"mu_s":/ {gsub(/[,]/, ""); m = $2}
    /"mu_s_ci95":/ {gsub(/[][,]/, " "); lo = $2; hi = $3}
    /"mu_s_true":/ {gsub(/,/, ""); t = $2}
    /"n_simulations":/ {gsub(/,/, ""); n = $2}
    END {print p "," t "," m "," lo "," hi "," n}' "$fit/summary.json" >> "fits$tag.csv.tmp"
done
mv "fits$tag.csv.tmp" "fits$tag.csv"
cat "fits$tag.csv"

if [[ $joint -eq 1 ]]; then
  "$granmem" --config protocol.toml calibrate --experiment "${names[0]}.h5" --out joint \
    --fit mu_s,mu_r --mu-s 0.05,0.12,0.3 --mu-r 0.004,0.012,0.036 --replicas 2 \
    --observables steady-state --threads 2 2> joint.log | tee joint.txt
fi
