#!/usr/bin/env bash
# Regenerates sample_data/scans/: a small packing simulated with granmem's DEM (400 grains
# of 2.5 mm radius in a 3 cm box under a lid, compressed cyclically by 5%), its packing
# after each of the first three cycles rendered as laser-sheet scans (12 px grains, slices
# 1.5 px apart, 8 bit, default artefacts, a seed per scan), with the truth of each scan.
# Deterministic: the same build gives the same files. Needs a built granmem (scripts/build.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
granmem=build/app/granmem
out=sample_data/scans
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$granmem" simulate --grains 400 --box 3cm --cycles 2 --amplitude 5% --threads 1 \
  --out "$work/packing.h5" --checkpoint "$work/packing.checkpoint.h5"
mkdir -p "$out"
for frame in 0 1 2; do
  "$granmem" render "$work/packing.h5" --frame "$frame" --diameter-px 12 \
    --slice-spacing-ratio 1.5 --bits 8 --seed $((frame + 1)) \
    --out "$out/scan$frame.tif" --truth "$out/truth$frame.csv"
done
