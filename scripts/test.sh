#!/usr/bin/env bash
# The whole test suite on a fresh Debian 12 machine: install what is needed, build, test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh -DGRANMEM_MPI=ON  # the MPI build: read-outs on 2 ranks are tested too
jobs=$(nproc 2>/dev/null || echo 2)
ctest --test-dir build --output-on-failure -j"$jobs"
