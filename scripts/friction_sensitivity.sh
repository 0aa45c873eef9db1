#!/usr/bin/env bash
# Which observables of the steady state identify the sliding friction (docs/CALIBRATION.md,
# issue 17): per run of scripts/quasistatic_study.sh at one inertial number and several
# frictions and seeds, the means over a window of late cycles of
#   dr        end-of-cycle displacement (drift removed, grains > 1 d from the walls), d
#   rot       single-axis rotational displacement (angle x d/2), d
#   phi_pos   bulk packing fraction from the positions (granmem analyze's per_frame)
#   z         coordination number from the positions (gap 2 %)
#   phi_lid   packing fraction from the lid height (the simulation's own observable)
#   force     force on the driven wall at full compression, N
# then, per observable, the seed-to-seed scatter s (from the pairs of seeds at each
# friction, pooled) and the local slope between neighbouring frictions of the seed means
# against ln mu_s: s / |slope| is the error in ln mu_s that one packing's value leaves.
#
#   scripts/friction_sensitivity.sh [--runs DIR] [--out DIR] [--granmem BIN] [--window A:B]
#                                   [--diameter 5mm]
#
# Writes per_run.csv and sensitivity.csv in --out (default docs/data/friction).
set -euo pipefail
source "$(dirname "$0")/lib/run_tables.sh"

root=$(cd "$(dirname "$0")/.." && pwd)
runs="$root/out/friction_scan"
out="$root/docs/data/friction"
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
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "friction_sensitivity.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
[[ -x $granmem ]] || { echo "friction_sensitivity.sh: no granmem at $granmem" >&2; exit 1; }
command -v h5dump > /dev/null || { echo "friction_sensitivity.sh: h5dump not found (hdf5-tools)" >&2; exit 1; }
mkdir -p "$out" "$runs/report"
d_m=$(in_metres "$diameter")
first=${window%%:*}
last=${window##*:}

names=$(for f in "$runs"/*.done; do if [[ -e $f ]]; then basename "$f" .done; fi; done)
[[ -n $names ]] || { echo "friction_sensitivity.sh: no finished runs in $runs" >&2; exit 1; }

per_run="$out/per_run.csv"
{
  echo "# means over cycles $window of each run (scripts/friction_sensitivity.sh); lengths in grain diameters"
  echo "mu_s,seed,dr,rot,phi_pos,z,phi_lid,force"
} > "$per_run"
for name in $names; do
  mu=$(echo "$name" | sed -E 's/^mu([^_]+)_seed.*$/\1/')
  seed=$(echo "$name" | sed -E 's/^.*_seed([^_]+)_.*$/\1/')
  h5="$runs/$name.h5"
  report="$runs/report/$name"
  [[ -s $report/per_frame.csv ]] ||
    "$granmem" analyze "$h5" --subtract-drift --wall-distance "$diameter" --out "$report" > /dev/null
  observable "$h5" packing_fraction > "$report.phi"
  observable "$h5" wall_force_full_compression > "$report.force"
  awk -F, -v mu="$mu" -v seed="$seed" -v d="$d_m" -v a="$first" -v b="$last" \
    -v phi="$report.phi" -v force="$report.force" '
    BEGIN { n = 0; while ((getline v < phi) > 0) p[n++] = v; n = 0; while ((getline v < force) > 0) f[n++] = v }
    /^#/ { next }
    /^frame/ { for (k = 1; k <= NF; k++) col[$k] = k; next }
    $1 >= a && $1 <= b {
      m++; dr += $col["mean_dr"] / d; rot += $col["mean_rot_disp"] / d
      pp += $col["packing_fraction"]; z += $col["coordination"]; pl += p[$1]; fo += f[$1]
    }
    END { printf "%s,%s,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", mu, seed, dr / m, rot / m, pp / m, z / m, pl / m, fo / m }' \
    "$report/per_frame.csv" >> "$per_run"
done

sens="$out/sensitivity.csv"
{
  echo "# per observable: seed-to-seed scatter s (pooled over the frictions with two seeds), then for each pair of neighbouring frictions the slope of the seed means against ln mu_s and s/|slope|, the error in ln mu_s one packing's value leaves"
  echo "observable,s,mu_lo,mu_hi,slope_per_ln_mu,sigma_ln_mu"
} > "$sens"
sort -t, -k1,1g -k2,2n <(grep -v '^#' "$per_run" | tail -n +2) | awk -F, '
  { mu[NR] = $1; for (k = 3; k <= 8; k++) v[NR, k] = $k; n = NR }
  END {
    split("dr rot phi_pos z phi_lid force", name, " ")
    for (k = 3; k <= 8; k++) {
      # the seeds of each friction
      m = 0; ss = 0; pairs = 0
      for (i = 1; i <= n; i++) {
        if (i == 1 || mu[i] != mu[i - 1]) { m++; f[m] = mu[i]; sum[m] = 0; cnt[m] = 0; first[m] = i }
        sum[m] += v[i, k]; cnt[m]++
      }
      for (j = 1; j <= m; j++) {
        mean[j] = sum[j] / cnt[j]
        if (cnt[j] >= 2) {
          for (i = first[j]; i < first[j] + cnt[j]; i++) { ss += (v[i, k] - mean[j]) ^ 2 }
          pairs += cnt[j] - 1
        }
      }
      s = pairs > 0 ? sqrt(ss / pairs) : 0
      for (j = 1; j < m; j++) {
        slope = (mean[j + 1] - mean[j]) / (log(f[j + 1]) - log(f[j]))
        printf "%s,%.4g,%s,%s,%.4g,%.3g\n", name[k - 2], s, f[j], f[j + 1], slope, slope != 0 ? s / (slope < 0 ? -slope : slope) : 1e9
      }
    }
  }' >> "$sens"
column -s, -t < "$sens" | sed -n '2,$p'

# The figure: each observable against mu_s, both seeds.
command -v gnuplot > /dev/null || { echo "friction_sensitivity.sh: gnuplot not found, no figure" >&2; exit 0; }
grep -v '^#' "$per_run" | tail -n +2 | sort -t, -k2,2n -k1,1g |
  awk -F, 'NR > 1 && $2 != seed { print "\n" } { seed = $2; print }' > "$out/per_run.dat"
seed_names=$(grep -v '^#' "$per_run" | tail -n +2 | cut -d, -f2 | sort -un | tr '\n' ' ')
seeds=$(echo $seed_names | wc -w)
gnuplot <<GNUPLOT
seed_names = "$seed_names"
colours = "#440154 #21918c #fde725 #3b528b #5ec962"
set terminal pngcairo size 1500,900 font "sans,11"
set output "$out/sensitivity.png"
set datafile separator ","
set multiplot layout 2,3 title "Steady state (cycles $window) against sliding friction: 1,500 grains, 5 cm box, 436 Pa, A = 1 %, one line per packing"
set logscale x
set xrange [0.04:0.6]
set xlabel "mu_s"
set xtics ("0.05" 0.05, "0.1" 0.1, "0.2" 0.2, "0.3" 0.3, "0.5" 0.5)
titles = "dr/d rot/d phi\\\\_pos z phi\\\\_lid force/N"
labels = "'end-of-cycle displacement / d' 'rotational displacement / d' 'bulk packing fraction (positions)' 'coordination (gap 2 %)' 'packing fraction (lid height)' 'wall force at full compression, N'"
do for [k = 3:8] {
  set ylabel word(labels, k - 2)
  if (k == 5 || k == 6 || k == 7) { set key top right } else { set key top left }
  plot for [i = 0:$((seeds - 1))] "$out/per_run.dat" index i using 1:k with linespoints \
       pt 7 lc rgb word(colours, i + 1) title sprintf("seed %s", word(seed_names, i + 1))
}
unset multiplot
GNUPLOT
echo "wrote $per_run, $sens and $out/sensitivity.png"
