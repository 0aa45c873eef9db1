#!/usr/bin/env bash
# Do the two engines agree? The same packings (granmem's deposit, one per seed) cycled by
# the embedded DEM and by LAMMPS (`simulate --engine lammps`), and their steady states
# compared with `granmem compare` (KS distance of the end-of-cycle translational and
# rotational displacements, drift removed, grains more than a diameter from the walls),
# against the yardstick of two seeds run by the same engine. Reduced scale at the paper's
# lid pressure: 1,500 grains of 5 mm in a 5 cm box, 436 Pa, A = 1 % of the box, mu_s 0.2.
#
#   scripts/engine_twin_study.sh [--out DIR] [--report DIR] [--jobs J] [--cycles C]
#                                [--window A:B] [--seeds "1 2 3"] [--grains N] [--ranks R]
#                                [--granmem BIN]
#
# Runs J simulations at a time (default 2; LAMMPS runs take R ranks each, default 1), each
# with a checkpoint (granmem) or a restart (LAMMPS) every 5 cycles: calling the script
# again with the same DIR skips finished runs and resumes the others. Progress:
# DIR/<run>.log. Then writes DIR/../report (--report; default docs/data/engine_twin):
# twin.csv (one row per compared pair), observables.csv (each run's packing fraction,
# force on the driven wall at full compression and contacts per grain, before the first
# cycle and as means over the window) and the compare figures of seed 1.
set -euo pipefail
source "$(dirname "$0")/lib/resumable_run.sh"
source "$(dirname "$0")/lib/run_tables.sh"

root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/out/engine_twin"
report="$root/docs/data/engine_twin"
granmem="$root/build/app/granmem"
jobs=2
cycles=30
window=""
seeds="1 2 3"
grains=1500
ranks=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out="$2"; shift ;;
    --report) report="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    --cycles) cycles="$2"; shift ;;
    --window) window="$2"; shift ;;
    --seeds) seeds="$2"; shift ;;
    --grains) grains="$2"; shift ;;
    --ranks) ranks="$2"; shift ;;
    --granmem) granmem="$2"; shift ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) echo "engine_twin_study.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
[[ -x $granmem ]] || { echo "engine_twin_study.sh: no granmem at $granmem (scripts/build.sh)" >&2; exit 1; }
command -v lmp > /dev/null || { echo "engine_twin_study.sh: no lmp (apt-get install lammps)" >&2; exit 1; }
[[ -n $window ]] || window="$((cycles - 9)):$cycles"
mkdir -p "$out" "$report"
case "$out" in /*) ;; *) out="$PWD/$out" ;; esac

# One run: finished (a .done marker), resumed from its checkpoint, or started.
run_one() {
  local engine=$1 seed=$2
  resumable_run "$out" "${engine}_seed${seed}" "$cycles" --grains "$grains" --box 5cm \
    --amplitude 1% --inertial-number 1e-3 --seed "$seed" --checkpoint-every 5 --engine "$engine" --ranks "$ranks"
}
export -f run_one
export out cycles grains granmem ranks

# LAMMPS runs first: they are the longer.
list=$(for e in lammps granmem; do for s in $seeds; do echo "$e $s"; done; done)
total=$(echo "$list" | wc -l)
echo "engine twin study: $total runs of $cycles cycles in $out, $jobs at a time"
echo "$list" | xargs -P "$jobs" -L 1 bash -c 'run_one "$@"' _
finished=$(ls "$out"/*.done 2> /dev/null | wc -l)
echo "finished: $finished of $total runs"
[[ $finished -eq $total ]] || exit 1

# ---- the comparisons: each seed across the engines, and seeds within each engine
compare() {  # a b
  local dir="$out/compare/$1-vs-$2"
  mkdir -p "$out/compare"
  [[ -s $dir/distances.csv ]] ||
    "$granmem" compare "$out/$1.h5" "$out/$2.h5" --window "$window" --wall-distance 5mm \
      --label-a "${1//_/ }" --label-b "${2//_/ }" --out "$dir" > "$dir.log" 2>&1
  # quantity (1 = dr, 2 = rot_disp): mean_a mean_b ks ks_p
  for q in 1 2; do
    awk -F, -v q="$q" -v a="$1" -v b="$2" -v kind="$3" '!/^#/ && $1 == q {
      printf "%s,%s,%s,%s,%s,%s,%s,%s\n", kind, a, b, (q == 1 ? "dr" : "rot_disp"), $4, $5, $8, $9 }' \
      "$dir/distances.csv"
  done
}
table="$report/twin.csv"
{
  echo "# engine twin study: $grains grains, 5 cm box, 436 Pa, A = 1 %, mu_s 0.2, $cycles cycles;"
  echo "# end-of-cycle displacements over cycles $window (drift removed, > 1 d from the walls), in grain diameters"
  echo "# made by: scripts/engine_twin_study.sh --cycles $cycles --seeds \"$seeds\" --grains $grains"
  echo "pair,a,b,quantity,mean_a_d,mean_b_d,ks,ks_p"
  for s in $seeds; do compare "granmem_seed$s" "lammps_seed$s" engines; done
  prev=""
  for s in $seeds; do
    if [[ -n $prev ]]; then
      compare "granmem_seed$prev" "granmem_seed$s" seeds_granmem
      compare "lammps_seed$prev" "lammps_seed$s" seeds_lammps
    fi
    prev=$s
  done
} > "$table.tmp"
mv "$table.tmp" "$table"
# ---- the runs' own observables: before the first cycle, and means over the window
observables="$report/observables.csv"
{
  echo "# engine twin study: each run's observables before the first cycle (_0) and as means over cycles $window"
  echo "engine,seed,packing_fraction_0,packing_fraction,wall_force_full_compression_N,contacts_per_grain"
  for e in granmem lammps; do
    for s in $seeds; do
      f="$out/${e}_seed$s.h5"
      mean() { observable "$f" "$1" | awk -v a="${window%%:*}" -v b="${window##*:}" \
        'NR - 1 >= a && NR - 1 <= b { s += $1; n++ } END { printf "%.6g", s / n }'; }
      echo "$e,$s,$(observable "$f" packing_fraction | head -1),$(mean packing_fraction),$(mean wall_force_full_compression),$(mean contacts_per_grain)"
    done
  done
} > "$observables.tmp"
mv "$observables.tmp" "$observables"
first=$(echo "$seeds" | awk '{print $1}')
for f in "$out/compare/granmem_seed$first-vs-lammps_seed$first"/*.png; do
  [[ -e $f ]] && cp "$f" "$report/"
done
echo "wrote $table and $observables"
column -s, -t < <(grep -v '^#' "$table")
