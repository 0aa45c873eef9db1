#!/usr/bin/env bash
# The paper's Fig. 5 at reduced scale: read-outs of packings prepared (trained) at different
# amplitudes, after the same number of training cycles, one curve per preparation amplitude,
# each amplitude dashed. Reads the <name>_curves.csv and <name>_signature.csv tables that
# scripts/memory_report.sh writes for each study.
#
#   scripts/preparation_figure.sh --cycles 100 --mu 0.2 [--data docs/data/memory]
#                                 [--out docs/data/memory/preparation] NAME...
#
# e.g. NAMEs A0.5 readout A2: the studies trained at 0.5 %, 1 % and 2 %.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
data="$root/docs/data/memory"
out="$data/preparation"
cycles=100
mu=0.2
names=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --cycles) cycles="$2"; shift ;;
    --mu) mu="$2"; shift ;;
    --data) data="$2"; shift ;;
    --out) out="$2"; shift ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    *) names+=("$1") ;;
  esac
  shift
done
[[ ${#names[@]} -gt 0 ]] || { echo "preparation_figure.sh: name the studies" >&2; exit 2; }

# One table: preparation amplitude, A', dr, error, rotation, error.
echo "training_amplitude_pct,amplitude_pct,dr_d,dr_err_d,rot_single_d,rot_single_err_d" > "$out.csv"
for n in "${names[@]}"; do
  a=$(awk -F, -v m="$mu" 'NR > 1 && $1 == m { print $3; exit }' "$data/${n}_signature.csv")
  awk -F, -v m="$mu" -v c="$cycles" -v a="$a" 'NR > 1 && $1 == m && $2 == c { print a "," $3 "," $5 "," $6 "," $9 "," $10 }' \
    "$data/${n}_curves.csv" >> "$out.csv"
done
preps=$(awk -F, 'NR > 1 { print $1 }' "$out.csv" | sort -g -u | tr '\n' ' ')

plot() {
  gnuplot <<GP
$1
set output "$2"
set datafile separator ","
set termoption noenhanced
set multiplot layout 1,2 title "mu_s = $mu, $cycles training cycles at the preparation amplitude (dashed); mean of the packings, error of the mean"
set logscale xy
set xrange [0.03:4]
set format x "%g"
set grid
set key top left
set xlabel "read-out amplitude A' (% of the box)"
preps = "$preps"
do for [k = 1:words(preps)] { set arrow k from real(word(preps, k)), graph 0 to real(word(preps, k)), graph 1 nohead dashtype 2 lc k }
do for [row = 1:2] {
  set ylabel (row == 1 ? "mean displacement (d)" : "mean rotational displacement (d)")
  set title (row == 1 ? "translations" : "single-axis rotations")
  col = (row == 1 ? 3 : 5)
  plot for [k = 1:words(preps)] "$out.csv" using (\$1 == real(word(preps, k)) ? \$2 : 1/0):col:(column(col + 1)) \
    with yerrorlines lc k pt 7 ps 0.6 title sprintf("prepared at %s %%", word(preps, k))
}
unset multiplot
GP
}
plot 'set terminal pngcairo size 1400,600 font ",10"' "$out.png"
plot 'set terminal svg size 1400,600 font "Arial,10"' "$out.svg"
echo "wrote $out.csv, $out.png, $out.svg"
