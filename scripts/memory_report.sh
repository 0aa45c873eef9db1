#!/usr/bin/env bash
# The tables and figures of docs/REPRODUCTION.md's memory findings from the read-outs of
# scripts/memory_study.sh (DIR/readout_mu<M>_seed<S>/{readout,memory}.csv).
#
#   scripts/memory_report.sh [--runs DIR] [--out DIR] [--name readout] [--title TEXT]
#                            [--granmem BIN] [--last 20]
#
# Writes in --out (default docs/data/memory):
#   <name>_all.csv       every read-out point (first read-out cycle): mu_s, seed, trained
#                        cycles, A', dr, MSD, rotations with their bootstrap errors
#   <name>_curves.csv    the curves averaged over seeds: mean, and the error of the mean
#                        from the seed-to-seed spread (the bootstrap error with one seed)
#   <name>_signature_all.csv, <name>_signature.csv   the memory signature (granmem
#                        readout's memory.csv) per packing, and averaged over seeds likewise
#   <name>.png, <name>.svg   translations (top) and single-axis rotations (bottom) against
#                        A', one column per mu_s, one curve per training length, the
#                        training amplitude dashed (the paper's Fig. 4)
#   <name>_training.csv  the trainings themselves (DIR/mu<M>_seed<S>.h5, `granmem compare`
#                        of seed 1 and seed 2 of each mu_s, drift removed): mean end-of-cycle
#                        displacement and single-axis rotation over the last --last cycles,
#                        KS distance between the seeds, relaxation exponents (Figs 2a, 3),
#                        the steady state fitted (relax_exp_*) and held at the mean of the
#                        last --last cycles as the paper does (held_exp_*)
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
runs="$root/out/memory"
out="$root/docs/data/memory"
name=readout
title="granmem read-out"
granmem="$root/build/app/granmem"
last=20
while [[ $# -gt 0 ]]; do
  case "$1" in
    --runs) runs="$2"; shift ;;
    --out) out="$2"; shift ;;
    --name) name="$2"; shift ;;
    --title) title="$2"; shift ;;
    --granmem) granmem="$2"; shift ;;
    --last) last="$2"; shift ;;
    -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
    *) echo "memory_report.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$out"

# Columns of a granmem CSV by name, comment lines skipped, with mu_s and seed in front.
gather() {  # file-in-each-readout-dir, columns..., filter on cycle (yes/no)
  local file=$1 cyclefilter=$2; shift 2
  local first=1
  for d in "$runs"/readout_mu*_seed*; do
    [[ -s $d/$file ]] || continue
    local tag=${d##*/readout_mu} mu seed
    mu=${tag%%_seed*}; seed=${tag##*_seed}
    awk -F, -v mu="$mu" -v seed="$seed" -v cols="$*" -v first=$first -v cf="$cyclefilter" '
      /^#/ { next }
      !header { header = 1; for (i = 1; i <= NF; i++) at[$i] = i; n = split(cols, c, " ");
                if (first) { printf "mu_s,seed"; for (k = 1; k <= n; k++) printf ",%s", c[k]; print "" }
                next }
      cf == "yes" && $at["cycle"] != 1 { next }
      { printf "%s,%s", mu, seed; for (k = 1; k <= n; k++) printf ",%s", $at[c[k]]; print "" }' "$d/$file"
    first=0
  done
}

gather readout.csv yes trained_cycles amplitude_pct dr_d dr_err_d msd_d2 msd_err_d2 \
  rot_single_d rot_single_err_d rot_full_d rot_full_err_d > "$out/${name}_all.csv"
gather memory.csv no trained_cycles training_amplitude_pct dr_dip dr_dip_err dr_over_untrained \
  dr_over_untrained_err rot_single_dip rot_single_dip_err rot_single_exp_below rot_single_exp_below_err rot_single_exp_above \
  rot_single_exp_above_err > "$out/${name}_signature_all.csv"
[[ $(wc -l < "$out/${name}_all.csv") -gt 1 ]] || { echo "memory_report.sh: no read-outs in $runs" >&2; exit 1; }

# Means over seeds of columns (value, error) pairs, grouped by the key columns: the error
# of a mean is the seeds' standard deviation / sqrt(n), or the one packing's own error.
average() {  # input, number of key columns after mu_s (1 or 2), value/error column pairs
  awk -F, -v keys="$2" '
    NR == 1 { printf "mu_s"; for (i = 3; i <= 2 + keys; i++) printf ",%s", $i; printf ",seeds";
              for (i = 3 + keys; i <= NF; i += 2) printf ",%s,%s", $i, $(i + 1); print ""; nf = NF; next }
    { key = $1; for (i = 3; i <= 2 + keys; i++) key = key "," $i
      if (!(key in n)) order[++groups] = key
      n[key]++
      for (i = 3 + keys; i <= NF; i += 2) {
        if ($i == "nan") { bad[key, i] = 1; continue }
        s[key, i] += $i; ss[key, i] += $i * $i; e[key, i] = $(i + 1) }
    }
    END { for (g = 1; g <= groups; g++) { key = order[g]; printf "%s,%d", key, n[key]
            for (i = 3 + keys; i <= nf; i += 2) {
              if (bad[key, i]) { printf ",nan,nan"; continue }
              m = s[key, i] / n[key]
              if (n[key] > 1) { v = (ss[key, i] - n[key] * m * m) / (n[key] - 1); if (v < 0) v = 0
                                err = sqrt(v / n[key]) } else err = e[key, i]
              printf ",%.6g,%.3g", m, err }
            print "" } }' "$1"
}
average "$out/${name}_all.csv" 2 > "$out/${name}_curves.csv"
average "$out/${name}_signature_all.csv" 2 > "$out/${name}_signature.csv"

mus=$(awk -F, 'NR > 1 { print $1 }' "$out/${name}_curves.csv" | sort -g -u | tr '\n' ' ')
lengths=$(awk -F, 'NR > 1 { print $2 }' "$out/${name}_curves.csv" | sort -g -u | tr '\n' ' ')
training=$(awk -F, 'NR > 1 && $4 != "nan" { print $4; exit }' "$out/${name}_signature_all.csv")
columns=$(echo $mus | wc -w)

plot() {  # terminal line, output file
  gnuplot <<GP
$1
set output "$2"
set datafile separator ","
set termoption noenhanced
set multiplot layout 2,$columns title "$title (first read-out cycle; mean of the packings, error of the mean)"
set logscale xy
set xrange [0.03:4]
set format x "%g"
set format y "%g"
set key top left font ",9"
set grid
mus = "$mus"
lengths = "$lengths"
A = ${training:-1}
set arrow 1 from A, graph 0 to A, graph 1 nohead dashtype 2 lc rgb "gray40"
do for [row = 1:2] {
  do for [m = 1:words(mus)] {
    mu = word(mus, m)
    set title sprintf("mu_s = %s: %s", mu, row == 1 ? "translations" : "single-axis rotations")
    set xlabel "read-out amplitude A' (% of the box)"
    set ylabel (row == 1 ? "mean displacement (d)" : "mean rotational displacement (d)")
    col = (row == 1 ? 5 : 11)
    plot for [l = 1:words(lengths)] "$out/${name}_curves.csv" \
      using (\$1 == real(mu) && \$2 == real(word(lengths, l)) ? \$3 : 1/0):col:(column(col + 1)) \
      with yerrorlines pt 7 ps 0.6 title sprintf("%s cycles", word(lengths, l))
  }
}
unset multiplot
GP
}
plot 'set terminal pngcairo size 1500,900 font ",10"' "$out/$name.png"
plot 'set terminal svg size 1500,900 font "Arial,10"' "$out/$name.svg"
# The trainings: seed 1 against seed 2 of each friction over the last cycles.
echo "mu_s,cycles,window,mean_dr_seed1_d,mean_dr_seed2_d,ks_dr,mean_rot_seed1_d,mean_rot_seed2_d,ks_rot,relax_exp_dr_seed1,relax_exp_dr_seed2,relax_exp_rot_seed1,relax_exp_rot_seed2,held_exp_dr_seed1,held_exp_dr_seed2,held_exp_rot_seed1,held_exp_rot_seed2" > "$out/${name}_training.csv"
for m in $mus; do
  a="$runs/mu${m}_seed1.h5" b="$runs/mu${m}_seed2.h5"
  [[ -s $a && -s $b ]] || continue
  cycles=$(h5dump -H -d /particles/grains/position/step "$a" | awk -F'[()]' '/DATASPACE/ { print $2 - 1; exit }')
  window="$((cycles - last + 1)):$cycles"
  said=$("$granmem" compare "$a" "$b" --window "$window" --out "$runs/compare_mu$m" \
    --label-a "mu_s $m seed 1" --label-b "mu_s $m seed 2" 2>&1)
  exps=$(echo "$said" | awk '/relaxation of/ { printf ",%s", $(NF - 2) }')
  # The paper's way: the steady state held at the mean of the last cycles, not fitted.
  held=$("$granmem" compare "$a" "$b" --window "$window" --steady-points "$last" \
    --out "$runs/compare_mu${m}_held" --label-a "mu_s $m seed 1" --label-b "mu_s $m seed 2" 2>&1 |
    awk '/relaxation of/ { printf ",%s", $(NF - 2) }')
  awk -F, -v m="$m" -v c="$cycles" -v w="$window" -v e="$exps" -v h="$held" '
    /^#/ || /^quantity/ { next }
    { mean1[$1] = $4; mean2[$1] = $5; ks[$1] = $8 }
    END { n = split(substr(e, 2), x, ","); nh = split(substr(h, 2), y, ",")
          printf "%s,%s,%s,%s,%s,%s,%s,%s,%s", m, c, w, mean1[1], mean2[1], ks[1], mean1[2], mean2[2], ks[2]
          for (k = 1; k <= 4; k++) printf ",%s", (k <= n ? x[k] : "nan")
          for (k = 1; k <= 4; k++) printf ",%s", (k <= nh ? y[k] : "nan"); print "" }' \
    "$runs/compare_mu$m/distances.csv" >> "$out/${name}_training.csv"
done

echo "wrote $out/${name}_all.csv, ${name}_curves.csv, ${name}_signature_all.csv, ${name}_signature.csv, $name.png, $name.svg, ${name}_training.csv"
