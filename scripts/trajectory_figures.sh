#!/usr/bin/env bash
# The paper's Figs 8 and 9 at reduced scale: in-cycle trajectories after training.
# From each friction's trained state (scripts/memory_study.sh), three more cycles at the
# training amplitude with every grain sampled --samples times a cycle; then
#  - Fig. 8: the y-z path of the mean position of a group of grains of the shear zone, the
#    --group grains that move most from the start of the first cycle to its full
#    compression (the colour of the paper's Fig. 1; a choice blind to whether they return);
#  - Fig. 9: the cavity (body z) axis of the group's grain that turns most, its tilt from
#    its start on the tangent plane of the unit sphere there (degrees: the paper draws the
#    sphere, on which a cycle's few degrees are too small to see);
# both coloured by time over the three cycles.
#
#   scripts/trajectory_figures.sh [--runs DIR] [--out DIR] [--granmem BIN] [--mu "0.05 0.2 0.5"]
#                                 [--seed 1] [--cycle 200] [--samples 100] [--group 20]
#
# Writes DIR/trajectories_mu<M>.h5 (+ _in_cycle.h5) under --runs, and trajectories_group.csv,
# trajectories_axis.csv, trajectories_loops.csv (each cycle's loop of the group's mean path:
# enclosed area, length, distance from its end to its start, in d), trajectories.png/.svg
# under --out (default docs/data/memory).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
runs="$root/out/memory"
out="$root/docs/data/memory"
granmem="$root/build/app/granmem"
mus="0.05 0.2 0.5"
seed=1
cycle=200
samples=100
group=20
while [[ $# -gt 0 ]]; do
  case "$1" in
    --runs) runs="$2"; shift ;;
    --out) out="$2"; shift ;;
    --granmem) granmem="$2"; shift ;;
    --mu) mus="$2"; shift ;;
    --seed) seed="$2"; shift ;;
    --cycle) cycle="$2"; shift ;;
    --samples) samples="$2"; shift ;;
    --group) group="$2"; shift ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    *) echo "trajectory_figures.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$out"
echo "mu_s,sample,cycle_fraction,dy_d,dz_d" > "$out/trajectories_group.csv"
echo "mu_s,grain,sample,cycle_fraction,ax,ay,az,u_deg,v_deg" > "$out/trajectories_axis.csv"
echo "mu_s,cycle,loop_area_d2,path_length_d,return_distance_d" > "$out/trajectories_loops.csv"

for m in $mus; do
  state="$runs/mu${m}_seed${seed}_state_cycle$cycle.h5"
  [[ -s $state ]] || { echo "trajectory_figures.sh: no $state" >&2; continue; }
  run="$runs/trajectories_mu$m.h5"
  if [[ ! -s ${run%.h5}_in_cycle.h5 ]]; then
    n=$(h5dump -H -d /particles/grains/id "$runs/mu${m}_seed${seed}.h5" | awk -F'[()]' '/DATASPACE/ { print $2; exit }')
    ids=$(seq -s, 0 $((n - 1)))
    OMP_NUM_THREADS=1 "$granmem" simulate --start-from "$state" --cycles 3 --threads 1 \
      --inertial-number 1e-3 --track "$ids" --samples-per-cycle "$samples" --out "$run" > "$runs/trajectories_mu$m.log" 2>&1
  fi
  "$granmem" export "$run" --out "$runs/trajectories_mu$m.end.dump" > /dev/null
  "$granmem" export "${run%.h5}_in_cycle.h5" --out "$runs/trajectories_mu$m.in.dump" > /dev/null
  # One awk over the start (end-of-cycle frame 0) and the samples: the group, its mean path,
  # and its most-turning grain's axis.
  awk -v m="$m" -v samples="$samples" -v group="$group" -v gout="$out/trajectories_group.csv" \
      -v aout="$out/trajectories_axis.csv" -v lout="$out/trajectories_loops.csv" '
    FNR == 1 { file++; frame = -1 }
    /^ITEM: TIMESTEP/ { frame++; next }
    /^ITEM: ATOMS/ { atoms = 1; next }
    /^ITEM/ { atoms = 0; next }
    !atoms { next }
    file == 1 && frame == 0 { y0[$1] = $3; z0[$1] = $4; d = 2 * $5; a0x[$1] = $6; a0y[$1] = $7; a0z[$1] = $8; next }
    file == 2 { y[frame, $1] = $3; z[frame, $1] = $4; ax[frame, $1] = $6; ay[frame, $1] = $7; az[frame, $1] = $8; ids[$1] = 1; last = frame }
    END {
      full = samples / 2 - 1   # sample 50 of 100: half the first cycle, full compression
      for (i in ids) { dy = y[full, i] - y0[i]; dz = z[full, i] - z0[i]; move[i] = sqrt(dy * dy + dz * dz) }
      for (k = 1; k <= group; k++) { best = ""; for (i in move) if (!(i in chosen) && (best == "" || move[i] > move[best])) best = i; chosen[best] = 1 }
      turn_best = ""
      for (i in chosen) { t = 0
        for (f = 0; f <= last; f++) { c = ax[f, i] * a0x[i] + ay[f, i] * a0y[i] + az[f, i] * a0z[i]; c = c < 0 ? -c : c; if (1 - c > t) t = 1 - c }
        if (turn_best == "" || t > turn) { turn = t; turn_best = i } }
      py = 0; pz = 0  # the group mean path, from the start
      for (f = 0; f <= last; f++) { sy = 0; sz = 0
        for (i in chosen) { sy += y[f, i] - y0[i]; sz += z[f, i] - z0[i] }
        gy = sy / group / d; gz = sz / group / d
        printf "%s,%d,%.4f,%.6g,%.6g\n", m, f + 1, (f + 1) / samples, gy, gz >> gout
        # The loop of each cycle: its enclosed area (shoelace, closed from its end back to its
        # start), length, and how far its end is from its start.
        if (f % samples == 0) { cy = py; cz = pz; area = 0; plen = 0 }
        area += py * gz - gy * pz; plen += sqrt((gy - py) ^ 2 + (gz - pz) ^ 2); py = gy; pz = gz
        if ((f + 1) % samples == 0) {
          area += py * cz - cy * pz
          printf "%s,%d,%.4g,%.4g,%.4g\n", m, (f + 1) / samples, (area < 0 ? -area : area) / 2, plen, sqrt((py - cy) ^ 2 + (pz - cz) ^ 2) >> lout }
        # The unsigned axis: the sign that keeps it near its start.
        i = turn_best; s = ax[f, i] * a0x[i] + ay[f, i] * a0y[i] + az[f, i] * a0z[i] < 0 ? -1 : 1
        bx = s * ax[f, i]; by = s * ay[f, i]; bz = s * az[f, i]
        # Tangent plane at the start: e1 = a0 x z (normalised), e2 = a0 x e1; angles in degrees.
        e1x = a0y[i]; e1y = -a0x[i]; e1z = 0; l = sqrt(e1x * e1x + e1y * e1y); e1x /= l; e1y /= l
        e2x = a0y[i] * e1z - a0z[i] * e1y; e2y = a0z[i] * e1x - a0x[i] * e1z; e2z = a0x[i] * e1y - a0y[i] * e1x
        u = bx * e1x + by * e1y + bz * e1z; v = bx * e2x + by * e2y + bz * e2z
        printf "%s,%s,%d,%.4f,%.6g,%.6g,%.6g,%.5g,%.5g\n", m, i, f + 1, (f + 1) / samples, bx, by, bz, atan2(u, sqrt(1 - u * u)) * 180 / 3.14159265, atan2(v, sqrt(1 - v * v)) * 180 / 3.14159265 >> aout }
    }' "$runs/trajectories_mu$m.end.dump" "$runs/trajectories_mu$m.in.dump"
  echo "trajectories of mu_s $m done"
done

columns=$(echo $mus | wc -w)
plot() {
  gnuplot <<GP
$1
set output "$2"
set datafile separator ","
set termoption noenhanced
set multiplot layout 2,$columns title "After $cycle training cycles (seed $seed): three cycles at the training amplitude, coloured by time (cycles)"
set palette defined (0 "blue", 1.5 "green", 3 "red")
set cbrange [0:3]
set cblabel "time (cycles)"
mus = "$mus"
do for [k = 1:words(mus)] {
  mu = word(mus, k)
  set title sprintf("mu_s = %s: mean path of $group shear-zone grains", mu)
  set xlabel "y displacement (d)"; set ylabel "z displacement (d)"
  set size square
  plot "$out/trajectories_group.csv" using (\$1 == real(mu) ? \$4 : 1/0):5:3 with lines lw 2 lc palette notitle
}
do for [k = 1:words(mus)] {
  mu = word(mus, k)
  set title sprintf("mu_s = %s: cavity axis of the group's most turning grain", mu)
  set xlabel "tilt along a0 x z (deg)"; set ylabel "tilt along a0 x (a0 x z) (deg)"
  set size square
  plot "$out/trajectories_axis.csv" using (\$1 == real(mu) ? \$8 : 1/0):9:4 with lines lw 2 lc palette notitle
}
unset multiplot
GP
}
plot 'set terminal pngcairo size 1500,1000 font ",10"' "$out/trajectories.png"
plot 'set terminal svg size 1500,1000 font "Arial,10"' "$out/trajectories.svg"
echo "wrote $out/trajectories_group.csv, trajectories_axis.csv, trajectories.png, trajectories.svg"
