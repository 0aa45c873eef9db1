#!/usr/bin/env bash
# The tables and figure of docs/QUASISTATIC.md from the runs of scripts/quasistatic_study.sh.
#
#   scripts/quasistatic_report.sh [--runs DIR] [--out DIR] [--granmem BIN] [--window A:B]
#                                 [--diameter 5mm]
#
# For every finished run (DIR/<run>.done): `granmem analyze` (drift removed, grains more
# than one diameter from the walls) gives the per-cycle means; `granmem compare` gives the
# steady state over the window (default the last 20 of 60 cycles) against the slowest drive
# of the same friction and seed (KS distance and p-value of the end-of-cycle translational
# and rotational displacements), and, as the yardstick, seed 1 against seed 2 at the same
# drive. The packing fraction and the force on the driven wall at full compression come
# from the runs' observables (h5dump). Writes per_cycle.csv, steady_state.csv and
# quasistatic.png (gnuplot) in --out (default docs/data/quasistatic).
set -euo pipefail
source "$(dirname "$0")/lib/run_tables.sh"

root=$(cd "$(dirname "$0")/.." && pwd)
runs="$root/out/quasistatic"
out="$root/docs/data/quasistatic"
granmem="$root/build/app/granmem"
window="41:60"
diameter="5mm"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --runs) runs="$2"; shift ;;
    --out) out="$2"; shift ;;
    --granmem) granmem="$2"; shift ;;
    --window) window="$2"; shift ;;
    --diameter) diameter="$2"; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "quasistatic_report.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
[[ -x $granmem ]] || { echo "quasistatic_report.sh: no granmem at $granmem" >&2; exit 1; }
command -v h5dump > /dev/null || { echo "quasistatic_report.sh: h5dump not found (hdf5-tools)" >&2; exit 1; }
mkdir -p "$out"
work="$runs/report"
mkdir -p "$work"
d_m=$(in_metres "$diameter")
first=${window%%:*}
last=${window##*:}

# name -> mu, seed, inertial number
parse() { echo "$1" | sed -E 's/^mu([^_]+)_seed([^_]+)_I(.+)$/\1 \2 \3/'; }
# "mean_a mean_b ks ks_p" of quantity row q (1 = dr, 2 = rot_disp) of a distances.csv
distance_row() { awk -F, -v q="$2" '!/^#/ && $1 == q { print $4, $5, $8, $9 }' "$1"; }
compare() {  # a.h5 b.h5 folder
  [[ -s $3/distances.csv ]] ||
    "$granmem" compare "$1" "$2" --window "$window" --wall-distance "$diameter" --out "$3" > "$3.log" 2>&1
}

names=$(for f in "$runs"/*.done; do if [[ -e $f ]]; then basename "$f" .done; fi; done)
[[ -n $names ]] || { echo "quasistatic_report.sh: no finished runs in $runs" >&2; exit 1; }

per_cycle="$out/per_cycle.csv"
echo "# per-cycle means of the end-of-cycle motion (drift removed, grains > 1 d from the walls); lengths in grain diameters" > "$per_cycle"
echo "mu_s,seed,inertial_number,cycle,mean_dr_d,mean_theta_axis_deg,packing_fraction,wall_force_full_compression_N" >> "$per_cycle"
for name in $names; do
  read -r mu seed inertial <<< "$(parse "$name")"
  h5="$runs/$name.h5"
  [[ -s $work/$name/per_frame.csv ]] ||
    "$granmem" analyze "$h5" --subtract-drift --wall-distance "$diameter" --out "$work/$name" > /dev/null
  observable "$h5" packing_fraction > "$work/$name.phi"
  observable "$h5" wall_force_full_compression > "$work/$name.force"
  awk -F, -v mu="$mu" -v seed="$seed" -v i="$inertial" -v d="$d_m" -v phi="$work/$name.phi" \
    -v force="$work/$name.force" '
    BEGIN { n = 0; while ((getline v < phi) > 0) p[n++] = v; n = 0; while ((getline v < force) > 0) f[n++] = v }
    /^#/ || /^frame/ { next }
    { printf "%s,%s,%s,%d,%.6g,%.6g,%.6g,%.6g\n", mu, seed, i, $1, $3 / d, $5, p[$1], f[$1] }' \
    "$work/$name/per_frame.csv" >> "$per_cycle"
done

steady="$out/steady_state.csv"
echo "# steady state over cycles $window: means of the end-of-cycle translational (dr) and rotational (rot_disp = single-axis angle x radius) displacements in grain diameters; KS distance and p-value against the slowest drive of the same mu_s and seed, and seed 1 against seed 2 (3 against 4, ...) at the same drive (the seed-to-seed yardstick), on the odd seed's row" > "$steady"
echo "mu_s,seed,inertial_number,mean_dr_d,mean_rot_disp_d,packing_fraction,wall_force_full_compression_N,ks_dr_vs_slowest,ks_p_dr_vs_slowest,ks_rot_vs_slowest,ks_p_rot_vs_slowest,ks_dr_seed1_vs_seed2,ks_rot_seed1_vs_seed2" >> "$steady"
for name in $names; do
  read -r mu seed inertial <<< "$(parse "$name")"
  slowest=$(for n in $names; do
    read -r m s i <<< "$(parse "$n")"
    if [[ $m == "$mu" && $s == "$seed" ]]; then echo "$i $n"; fi
  done | sort -g | head -1 | cut -d' ' -f2)
  compare "$runs/$slowest.h5" "$runs/$name.h5" "$work/vs_slowest_$name"
  read -r _ dr _ _ <<< "$(distance_row "$work/vs_slowest_$name/distances.csv" 1)"
  read -r _ rot _ _ <<< "$(distance_row "$work/vs_slowest_$name/distances.csv" 2)"
  if [[ $slowest == "$name" ]]; then
    ks="nan,nan,nan,nan"
  else
    ks=$(distance_row "$work/vs_slowest_$name/distances.csv" 1 | awk '{ printf "%s,%s", $3, $4 }'),$(distance_row "$work/vs_slowest_$name/distances.csv" 2 | awk '{ printf "%s,%s", $3, $4 }')
  fi
  other="mu${mu}_seed$((seed + 1))_I${inertial}"  # pairs of seeds: 1 with 2, 3 with 4, ...
  if ((seed % 2 == 1)) && [[ -e $runs/$other.done ]]; then
    pair="$work/seeds${seed}_mu${mu}_I${inertial}"
    compare "$runs/$name.h5" "$runs/$other.h5" "$pair"
    seeds=$(distance_row "$pair/distances.csv" 1 | awk '{ printf "%s", $3 }'),$(distance_row "$pair/distances.csv" 2 | awk '{ printf "%s", $3 }')
  else
    seeds="nan,nan"
  fi
  phi=$(awk -v a="$first" -v b="$last" 'NR - 1 >= a && NR - 1 <= b { s += $1; n++ } END { printf "%.6g", s / n }' "$work/$name.phi")
  force=$(awk -v a="$first" -v b="$last" 'NR - 1 >= a && NR - 1 <= b { s += $1; n++ } END { printf "%.6g", s / n }' "$work/$name.force")
  echo "$mu,$seed,$inertial,$dr,$rot,$phi,$force,$ks,$seeds" >> "$steady"
done
sort -t, -k1,1g -k2,2n -k3,3g -o "$steady.body" <(grep -v "^#\|^mu_s" "$steady")
{ grep "^#\|^mu_s" "$steady"; cat "$steady.body"; } > "$steady.tmp" && mv "$steady.tmp" "$steady" && rm "$steady.body"

# The figure: per-cycle means for each drive (one panel per friction; lines seed 1, points
# seed 2), and the steady state against the inertial number.
inertials=$(grep -v "^#\|^mu_s" "$steady" | cut -d, -f3 | sort -gu | tr '\n' ',' | sed 's/,$//')
frictions=$(grep -v "^#\|^mu_s" "$steady" | cut -d, -f1 | sort -gu | tr '\n' ',' | sed 's/,$//')
seeds=$(grep -v "^#\|^mu_s" "$steady" | cut -d, -f2 | sort -gu | tr '\n' ',' | sed 's/,$//')
gnuplot <<EOF
set terminal pngcairo size 1400,1400 font ",11"
set output "$out/quasistatic.png"
set datafile separator ","
set termoption noenhanced
array I[$(echo "$inertials" | tr ',' '\n' | wc -l)] = [$inertials]
array M[$(echo "$frictions" | tr ',' '\n' | wc -l)] = [$frictions]
array S[$(echo "$seeds" | tr ',' '\n' | wc -l)] = [$seeds]
is(x, y) = abs(x / y - 1) < 1e-9
set multiplot layout 3,2 title "Quasi-static limit: 1,500 grains, 5 cm box, lid 436 Pa, A = 1 % (drift removed, grains > 1 d from the walls)"
set key top right
set xlabel "cycle"
set logscale y
do for [m = 1:|M|] {
  set title sprintf("mu_s = %g: per-cycle mean end-of-cycle displacement (lines seed 1, points seed 2)", M[m])
  set ylabel "mean dr (grain diameters)"
  plot for [k = 1:|I|] "$per_cycle" using ((is(\$1, M[m]) && \$2 == 1 && is(\$3, I[k])) ? \$4 : NaN):5 with lines lw 2 lc k title sprintf("I = %g", I[k]), \
       for [k = 1:|I|] "$per_cycle" using ((is(\$1, M[m]) && \$2 == 2 && is(\$3, I[k])) ? \$4 : NaN):5 with points pt 7 ps 0.4 lc k notitle
}
unset logscale y
set logscale x
set xlabel "inertial number I"
set key top left
set title "steady state (cycles $window): mean end-of-cycle displacement"
set ylabel "mean dr (grain diameters)"
plot for [m = 1:|M|] for [s = 1:|S|] "$steady" using ((is(\$1, M[m]) && \$2 == S[s]) ? \$3 : NaN):4 with linespoints lw 2 lc m pt 4 + s title sprintf("mu_s %g, seed %d", M[m], S[s])
set title "steady state: mean rotational displacement (single-axis angle x radius)"
set ylabel "mean rot_disp (grain diameters)"
plot for [m = 1:|M|] for [s = 1:|S|] "$steady" using ((is(\$1, M[m]) && \$2 == S[s]) ? \$3 : NaN):5 with linespoints lw 2 lc m pt 4 + s title sprintf("mu_s %g, seed %d", M[m], S[s])
set key center left
set title "steady state: packing fraction"
set ylabel "packing fraction"
plot for [m = 1:|M|] for [s = 1:|S|] "$steady" using ((is(\$1, M[m]) && \$2 == S[s]) ? \$3 : NaN):6 with linespoints lw 2 lc m pt 4 + s title sprintf("mu_s %g, seed %d", M[m], S[s])
set key center right
set title "steady state: force on the driven wall at full compression"
set ylabel "force (N)"
plot for [m = 1:|M|] for [s = 1:|S|] "$steady" using ((is(\$1, M[m]) && \$2 == S[s]) ? \$3 : NaN):7 with linespoints lw 2 lc m pt 4 + s title sprintf("mu_s %g, seed %d", M[m], S[s])
unset multiplot
EOF
echo "wrote $per_cycle, $steady, $out/quasistatic.png"
