#!/usr/bin/env bash
# The main job on the sample data: install what is needed, build, then import the sample
# tracked grains and analyse their displacements and rotations; track the sample scans
# (locate, link) and analyse those too. Output in out/sample/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
granmem=build/app/granmem
out=out/sample
mkdir -p "$out"
set -x
"$granmem" --config sample_data/sample.toml import sample_data/tracked_grains.csv --out "$out/run.h5"
"$granmem" info "$out/run.h5"
"$granmem" --config sample_data/sample.toml analyze "$out/run.h5" --out "$out/analysis"
# The experimental pipeline on the sample scans: locate and link, then analyse the tracks.
"$granmem" track sample_data/scans/scan*.tif --diameter 5mm --out "$out/tracks.h5" \
  --detections "$out/detections"
"$granmem" analyze "$out/tracks.h5" --out "$out/tracks_analysis"
