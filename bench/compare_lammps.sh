#!/usr/bin/env bash
# granmem's DEM against LAMMPS (Debian 12 `lammps`, 29Sep2021) on the same grains and the
# same contact law (bench/lammps/contact_model.lmp). Figures: docs/BENCHMARKS.md.
#
#   bench/compare_lammps.sh            N = 2,000 (L = 7 cm): a few minutes
#   bench/compare_lammps.sh --full     also N = 20,000 (L = 15 cm): ~15 min on a quiet machine
#
# Options: --full; --native (also time a build for this machine's processor,
# -DGRANMEM_NATIVE=ON, in <build>-native); --sizes "2000 20000"; --steps N (timed steps, default 20000 for
# N <= 5000 and 5000 above); --seed S (1); --settle-threads T (granmem threads and LAMMPS
# ranks for settling, 2); --limit SECONDS (each settle and timed run is stopped after this
# long; default none); --out DIR (out/compare_lammps); --build DIR (build-bench-lmp);
# --skip-build; --reuse (keep the settled packings and settle results already in DIR:
# only the timings are run again).
#
# For each size: (0, once) a contact check, a few grains under a lid run by both codes;
# (a) physics: granmem and LAMMPS each settle the grains dem_bench inserts (same positions,
# radii and velocities as granmem::deposit with that seed), side by side; (b) timing: both
# run granmem's settled packing (exported) for nsteps while the y = 0 wall moves 0 -> A -> 0
# (A = 1% of L), granmem on 1 and 2 OpenMP threads, LAMMPS on 1 and 2 MPI ranks; particle-
# steps per second, the ratio granmem/LAMMPS and peak memory (/usr/bin/time -v).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
sizes="2000"
steps=""
seed=1
settle_threads=2
limit=""
out="$root/out/compare_lammps"
build="$root/build-bench-lmp"
skip_build=0
reuse=0
native=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --full) sizes="2000 20000" ;;
    --native) native=1 ;;
    --sizes) sizes="$2"; shift ;;
    --steps) steps="$2"; shift ;;
    --seed) seed="$2"; shift ;;
    --settle-threads) settle_threads="$2"; shift ;;
    --limit) limit="$2"; shift ;;
    --out) out="$2"; shift ;;
    --build) build="$2"; shift ;;
    --skip-build) skip_build=1 ;;
    --reuse) reuse=1 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    *) echo "compare_lammps.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
case "$out" in /*) ;; *) out="$PWD/$out" ;; esac
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
mkdir -p "$out"
summary="$out/summary.txt"
: > "$summary"
say() { echo "$@" | tee -a "$summary"; }

# ---- LAMMPS and the build
if ! command -v lmp > /dev/null; then
  echo "installing lammps (apt-get)" >&2
  sudo=""; [[ $(id -u) -ne 0 ]] && sudo="sudo"
  $sudo apt-get install -y lammps > "$out/apt.log" 2>&1 || {
    $sudo apt-get update > /dev/null && $sudo apt-get install -y lammps > "$out/apt.log" 2>&1
  }
fi
command -v mpirun > /dev/null || { echo "mpirun not found (openmpi-bin)" >&2; exit 1; }
if [[ $skip_build -eq 0 ]]; then
  cmake -S "$root" -B "$build" -DGRANMEM_BUILD_BENCH=ON -DGRANMEM_BUILD_TESTS=OFF \
    > "$out/cmake.log" 2>&1
  cmake --build "$build" -j2 --target dem_bench >> "$out/cmake.log" 2>&1 ||
    { tail -30 "$out/cmake.log" >&2; exit 1; }
  if [[ $native -eq 1 ]]; then
    cmake -S "$root" -B "$build-native" -DGRANMEM_BUILD_BENCH=ON -DGRANMEM_BUILD_TESTS=OFF \
      -DGRANMEM_NATIVE=ON >> "$out/cmake.log" 2>&1
    cmake --build "$build-native" -j2 --target dem_bench >> "$out/cmake.log" 2>&1 ||
      { tail -30 "$out/cmake.log" >&2; exit 1; }
  fi
fi
bench="$build/bench/dem_bench"
lammps_dir="$root/bench/lammps"
export OMP_NUM_THREADS=1  # LAMMPS; dem_bench sets its own thread count
mpi=(mpirun --allow-run-as-root -np 2)

# key=value from a line of dem_bench or the LAMMPS inputs
field() { grep -o "$1=[^ ]*" | head -1 | cut -d= -f2; }
# LAMMPS loop time in seconds
loop_time() { grep -m1 "^Loop time of" "$1" | awk '{print $4}'; }
# peak RSS in MiB from /usr/bin/time -v output: largest process, and all processes summed
rss_max() { grep "Maximum resident set size" "$1" | awk '{ if ($NF > m) m = $NF } END { printf "%.0f", m / 1024 }'; }
rss_sum() { grep "Maximum resident set size" "$1" | awk '{ s += $NF } END { printf "%.0f", s / 1024 }'; }
reldiff() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%+.2f%%", 100 * (a - b) / b }'; }
run_limited() { if [[ -n $limit ]]; then timeout "$limit" "$@"; else "$@"; fi; }
lmp_in() { (cd "$lammps_dir" && run_limited "$@"); }

say "granmem vs LAMMPS, $(date -u +%Y-%m-%dT%H:%MZ), $(getconf _NPROCESSORS_ONLN) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
say "load average before: $(cut -d' ' -f1-3 /proc/loadavg)   granmem $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')$(git -C "$root" diff --quiet 2>/dev/null || echo '+changes')$([[ $skip_build -eq 1 ]] && echo ' (source; binary not rebuilt)'), LAMMPS $(lmp -h 2> /dev/null | grep -m1 -o '[0-9]* [A-Z][a-z]* 20[0-9][0-9].*' || true)"

# ---- 0. contact check: the same few grains, floor, side wall and lid in both codes
"$bench" contact-check "$out/check.data" 400 > "$out/check_granmem.txt"
lmp_in lmp -in in.contact_check.lmp -var data "$out/check.data" -var nsteps 400 \
  -var out "$out/check_lammps.dump" -log none > "$out/check_lammps.log" 2>&1
say ""
say "contact check (4 grains, floor, side wall, lid; 400 steps): largest difference granmem - LAMMPS"
awk 'FNR == NR { if ($1 == "grain") for (k = 3; k <= 11; k++) g[$2, k] = $k; next }
     NF == 10 && $1 ~ /^[0-9]+$/ { for (k = 2; k <= 10; k++) { d = g[$1, k + 1] - $k; if (d < 0) d = -d;
       c = (k <= 4) ? 1 : (k <= 7) ? 2 : 3; if (d > m[c]) m[c] = d } }
     END { printf "  position %.2g cm, velocity %.2g cm/s, angular velocity %.2g rad/s\n", m[1], m[2], m[3] }' \
  "$out/check_granmem.txt" "$out/check_lammps.dump" | tee -a "$summary"
say "  lid height: granmem $(awk '$1 == "lid" {print $2}' "$out/check_granmem.txt") cm, LAMMPS $(awk '$1 == "lid" {print $2}' "$out/check_lammps.log") cm"

for n in $sizes; do
  if [[ $n -le 5000 ]]; then box=7; else box=15; fi
  nsteps=${steps:-$([[ $n -le 5000 ]] && echo 20000 || echo 5000)}
  tag="n$n"
  say ""
  say "==== N = $n, L = $box cm, seed $seed"

  # ---- (a) physics: both settle the same inserted grains
  if [[ $reuse -eq 1 && -s $out/$tag.settled.h5 && -s $out/$tag.settle_granmem.out ]] &&
    grep -q "^LAMMPS settle:" "$out/$tag.settle_lammps.out" 2> /dev/null; then
    say "(settled packings reused from an earlier run in $out)"
  else
    "$bench" insert "$n" "$box" "$seed" "$out/$tag.inserted.data" > /dev/null
    if ! run_limited "$bench" settle "$n" "$box" "$seed" "$out/$tag.settled.h5" "$settle_threads" \
      > "$out/$tag.settle_granmem.out" 2> "$out/$tag.settle_granmem.log"; then
      say "granmem settle failed or ran out of time: $out/$tag.settle_granmem.log"; continue
    fi
    if [[ $settle_threads -gt 1 ]]; then
      settle_lmp=(mpirun --allow-run-as-root -np "$settle_threads" lmp)
    else
      settle_lmp=(lmp)
    fi
    lmp_in "${settle_lmp[@]}" -in in.settle.lmp -var data "$out/$tag.inserted.data" \
      -log "$out/$tag.settle_lammps.log" > "$out/$tag.settle_lammps.out" 2>&1 || true
  fi
  gline=$(cat "$out/$tag.settle_granmem.out")
  if ! lline=$(grep "^LAMMPS settle:" "$out/$tag.settle_lammps.out"); then
    say "LAMMPS settle failed or ran out of time: $out/$tag.settle_lammps.out"; continue
  fi
  gphi=$(echo "$gline" | field packing_fraction); lphi=$(echo "$lline" | field packing_fraction)
  glid=$(echo "$gline" | field lid_height_cm); llid=$(echo "$lline" | field lid_height_cm)
  gz=$(echo "$gline" | field contacts_per_grain); lz=$(echo "$lline" | field contacts_per_grain)
  gt=$(echo "$gline" | field settling_time_s); lt=$(echo "$lline" | field settling_time_s)
  say "settled from the same insertion     granmem     LAMMPS   granmem/LAMMPS - 1"
  printf "  packing fraction under the lid   %8.4f   %8.4f   %s\n" "$gphi" "$lphi" "$(reldiff "$gphi" "$lphi")" | tee -a "$summary"
  printf "  lid height, cm                   %8.3f   %8.3f   %s\n" "$glid" "$llid" "$(reldiff "$glid" "$llid")" | tee -a "$summary"
  printf "  contacts per grain               %8.3f   %8.3f   %s\n" "$gz" "$lz" "$(reldiff "$gz" "$lz")" | tee -a "$summary"
  printf "  simulated settling time, s       %8.2f   %8.2f\n" "$gt" "$lt" | tee -a "$summary"

  # ---- (b) timing on granmem's settled packing
  "$bench" export "$out/$tag.settled.h5" "$out/$tag.settled.data" > /dev/null
  load=$(cut -d' ' -f1 /proc/loadavg)
  if awk -v l="$load" 'BEGIN { exit !(l > 0.5) }'; then
    say "WARNING: load average $load before timing: other processes share the cores, timings are low"
  fi
  say "timed: $nsteps steps, y = 0 wall 0 -> A -> 0 (cosine), A = 1% of L"
  say "                           particle-steps/s   peak RSS (MiB)   lid after (cm)"
  declare -A rate=()
  builds=("g:$bench:granmem")
  [[ $native -eq 1 ]] && builds+=("n:$build-native/bench/dem_bench:native ")
  for b in "${builds[@]}"; do
    IFS=: read -r key binary label <<< "$b"
    for t in 1 2; do
      log="$out/$tag.time_${label// /}_t$t.log"
      run_limited /usr/bin/time -v "$binary" time "$out/$tag.settled.h5" "$nsteps" "$t" > "$log" 2>&1 || true
      rate[$key$t]=$(grep "^granmem time:" "$log" | field particle_steps_per_s)
      printf "  %s, %d thread%s        %10.3g        %8s         %s\n" "$label" "$t" "$([[ $t -gt 1 ]] && echo s || echo ' ')" \
        "${rate[$key$t]:-nan}" "$(rss_max "$log")" "$(grep "^granmem time:" "$log" | field lid_cm_after)" | tee -a "$summary"
    done
  done
  for p in 1 2; do
    log="$out/$tag.time_lammps_np$p.log"
    if [[ $p -eq 1 ]]; then launch=(/usr/bin/time -v lmp); else launch=("${mpi[@]}" /usr/bin/time -v lmp); fi
    lmp_in "${launch[@]}" -in in.bench.lmp -var data "$out/$tag.settled.data" -var nsteps "$nsteps" \
      -log none > "$log" 2>&1 || true
    lt=$(loop_time "$log")
    rate[l$p]=$(awk -v n="$n" -v s="$nsteps" -v t="$lt" 'BEGIN { if (t > 0) printf "%.6g", n * s / t; else print "nan" }')
    mem="$(rss_max "$log")"; [[ $p -gt 1 ]] && mem="$mem x$p (sum $(rss_sum "$log"))"
    printf "  LAMMPS, %d rank%s           %10.3g        %-16s %s\n" "$p" "$([[ $p -gt 1 ]] && echo s || echo ' ')" \
      "${rate[l$p]}" "$mem" "$(grep "^LAMMPS time:" "$log" | field lid_cm_after)" | tee -a "$summary"
  done
  for b in "${builds[@]}"; do
    IFS=: read -r key binary label <<< "$b"
    for t in 1 2; do
      ratio=$(awk -v a="${rate[$key$t]:-0}" -v b="${rate[l$t]:-0}" 'BEGIN { if (a > 0 && b > 0) printf "%.2f", a / b; else print "n/a" }')
      say "  ${label// /}/LAMMPS at $t thread$([[ $t -gt 1 ]] && echo s)/rank$([[ $t -gt 1 ]] && echo s): $ratio"
    done
  done
  spc=$(grep -h "^granmem time:" "$out/$tag.time_granmem_t"*.log | head -1 | field steps_per_cycle_paper)
  best=$(awk -v a="${rate[g1]:-0}" -v b="${rate[g2]:-0}" 'BEGIN { print (a > b ? a : b) }')
  if [[ -n $spc && $best != 0 && $n -ge 20000 ]]; then  # a rate measured at 20,000 grains
    say "  paper run (20,000 grains x 500 cycles x $spc steps) at granmem's best rate here: $(awk -v r="$best" -v s="$spc" 'BEGIN { printf "%.0f h", 2e4 * 500 * s / r / 3600 }')"
  fi
done
say ""
say "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
say "logs and data: $out"
