#!/usr/bin/env bash
# The quasi-static study of docs/QUASISTATIC.md: the same packings driven at several
# inertial numbers (cycle periods), to find the fastest drive whose steady state agrees
# with the slowest. Reduced scale at the paper's lid pressure: 1,500 grains of 5 mm in a
# 5 cm box under 0.1111 kg (1 kg on 15 x 15 cm = 436 Pa), A = 1 % of the box.
#
#   scripts/quasistatic_study.sh [--out DIR] [--jobs J] [--granmem BIN] [--cycles C]
#                                [--inertial "3e-4 1e-3 3e-3 1e-2"] [--mu "0.05 0.5"]
#                                [--seeds "1 2"] [--grains N]
#
# Runs J simulations at a time (default 2), one thread each, longest first. Every run
# writes a checkpoint every 5 cycles: calling the script again with the same DIR skips
# finished runs and resumes the others where they stopped (a killed session loses at most
# 5 cycles per run). Each run deposits its own packing from its seed, so the runs of one
# (mu_s, seed) start from the same packing, bit for bit. Progress: DIR/<run>.log.
set -euo pipefail
source "$(dirname "$0")/lib/resumable_run.sh"

root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/out/quasistatic"
jobs=2
granmem="$root/build/app/granmem"
cycles=60
inertial="3e-4 1e-3 3e-3 1e-2"
mus="0.05 0.5"
seeds="1 2"
grains=1500
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    --granmem) granmem="$2"; shift ;;
    --cycles) cycles="$2"; shift ;;
    --inertial) inertial="$2"; shift ;;
    --mu) mus="$2"; shift ;;
    --seeds) seeds="$2"; shift ;;
    --grains) grains="$2"; shift ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) echo "quasistatic_study.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
[[ -x $granmem ]] || { echo "quasistatic_study.sh: no granmem at $granmem (scripts/build.sh)" >&2; exit 1; }
mkdir -p "$out"
case "$out" in /*) ;; *) out="$PWD/$out" ;; esac

# One run: finished (a .done marker), resumed from its checkpoint, or started.
run_one() {
  local name=$1 mu=$2 seed=$3 inertial=$4
  resumable_run "$out" "$name" "$cycles" --grains "$grains" --box 5cm --lid-mass 0.1111kg \
    --amplitude 1% --mu-s "$mu" --seed "$seed" --inertial-number "$inertial" --checkpoint-every 5
}
export -f run_one
export out cycles grains granmem

# Longest first: a run's cost is proportional to 1 / inertial number.
list=$(for i in $inertial; do for m in $mus; do for s in $seeds; do
  echo "$i mu${m}_seed${s}_I${i} $m $s $i"
done; done; done | sort -g -k1 | cut -d' ' -f2-)
total=$(echo "$list" | wc -l)
echo "quasistatic study: $total runs of $cycles cycles in $out, $jobs at a time"
echo "$list" | xargs -P "$jobs" -L 1 bash -c 'run_one "$@"' _
echo "finished: $(ls "$out"/*.done 2> /dev/null | wc -l) of $total runs"
