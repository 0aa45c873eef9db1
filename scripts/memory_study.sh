#!/usr/bin/env bash
# The memory study of docs/REPRODUCTION.md at reduced scale: packings trained at A = 1 %
# of the box (the paper's asymmetric drive), their states kept along the training, each
# read out by a parallel sweep of amplitudes. 1,500 grains of 5 mm in a 5 cm box under
# the paper's lid pressure (436 Pa), quasi-static drive (I = 1e-3).
#
#   scripts/memory_study.sh [--out DIR] [--jobs J] [--granmem BIN] [--cycles C]
#                           [--mu "0.05 0.2 0.5"] [--seeds "1 2"] [--grains N]
#                           [--amplitude 1%] [--drive asymmetric] [--keep "0,10,50,100,200,400"]
#                           [--amplitudes 0.05%:2.5%:12] [--stage train|readout|all]
#
# Training: J runs at a time (default 2), one thread each, checkpointed every 10 cycles:
# calling the script again with the same DIR skips finished runs and resumes the others
# (a killed session loses at most 10 cycles a run); a larger --cycles continues finished
# runs. Read-out: `granmem readout` of every kept state of each run, J runs at a time;
# finished read-out runs are reused. Progress: DIR/<run>.log, DIR/<run>.readout.log.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/out/memory"
jobs=2
granmem="$root/build/app/granmem"
cycles=200
mus="0.05 0.2 0.5"
seeds="1 2"
grains=1500
amplitude=1%
drive=asymmetric
keep=0,10,50,100,200,400
amplitudes=0.05%:2.5%:12
stage=all
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    --granmem) granmem="$2"; shift ;;
    --cycles) cycles="$2"; shift ;;
    --mu) mus="$2"; shift ;;
    --seeds) seeds="$2"; shift ;;
    --grains) grains="$2"; shift ;;
    --amplitude) amplitude="$2"; shift ;;
    --drive) drive="$2"; shift ;;
    --keep) keep="$2"; shift ;;
    --amplitudes) amplitudes="$2"; shift ;;
    --stage) stage="$2"; shift ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "memory_study.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
[[ -x $granmem ]] || { echo "memory_study.sh: no granmem at $granmem (scripts/build.sh)" >&2; exit 1; }
mkdir -p "$out"
case "$out" in /*) ;; *) out="$PWD/$out" ;; esac

# One training run: resumed from its checkpoint (to more cycles if asked), or started.
train_one() {
  local name=$1 mu=$2 seed=$3
  local h5="$out/$name.h5" ckpt="$out/$name.checkpoint.h5" log="$out/$name.log"
  local args
  if [[ -s $ckpt ]]; then
    args=(--resume "$ckpt" --cycles "$cycles")
  else
    rm -f "$h5"
    # I = 1e-3: the drive docs/MEMORY.md's numbers were measured at (the default then)
    args=(--grains "$grains" --box 5cm --amplitude "$amplitude" --drive "$drive" --mu-s "$mu"
          --inertial-number 1e-3
          --seed "$seed" --cycles "$cycles" --keep-states "$keep" --checkpoint-every 10
          --out "$h5" --checkpoint "$ckpt")
  fi
  if OMP_NUM_THREADS=1 "$granmem" simulate --threads 1 "${args[@]}" >> "$log" 2>&1; then
    echo "trained: $name ($cycles cycles)"
  else
    echo "failed or stopped: $name (see $log)" >&2
    return 1
  fi
}
export -f train_one
export out cycles grains granmem amplitude drive keep

runs=$(for m in $mus; do for s in $seeds; do echo "mu${m}_seed${s} $m $s"; done; done)
if [[ $stage == all || $stage == train ]]; then
  echo "memory study: $(echo "$runs" | wc -l) trainings of $cycles cycles in $out, $jobs at a time"
  echo "$runs" | xargs -P "$jobs" -L 1 bash -c 'train_one "$@"' _
fi
if [[ $stage == all || $stage == readout ]]; then
  while read -r name mu seed; do
    states=()
    for c in ${keep//,/ }; do
      f="$out/${name}_state_cycle$c.h5"
      [[ -s $f ]] && states+=("$f")
    done
    [[ ${#states[@]} -gt 0 ]] || { echo "no kept states of $name yet" >&2; continue; }
    echo "reading out $name: ${#states[@]} states"
    OMP_NUM_THREADS=1 "$granmem" readout --from "${states[@]}" --amplitudes "$amplitudes" \
      --drive "$drive" --inertial-number 1e-3 --parallel "$jobs" --out "$out/readout_$name" \
      >> "$out/$name.readout.log" 2>&1 || { echo "read-out failed: $name" >&2; exit 1; }
  done <<< "$runs"
  echo "read-outs: $out/readout_*/readout.csv"
fi
