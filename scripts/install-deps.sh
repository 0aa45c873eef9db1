#!/usr/bin/env bash
# Installs the Debian 12 packages granmem needs, skipping those already there, and any
# packages named as arguments (scripts/sanitize.sh: clang and its sanitizer runtimes).
# Runs as root, or through sudo when there is one.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev libhdf5-dev hdf5-tools libcli11-dev libopencv-dev libceres-dev libtiff-dev
  libgtest-dev libgmock-dev libbenchmark-dev libfmt-dev libnanoflann-dev nlohmann-json3-dev
  gnuplot-nox
  libopenmpi-dev openmpi-bin
  lammps
  python3-dev pybind11-dev python3-numpy python3-pandas python3-pytest python3-matplotlib
  python3-h5py python3-ase python3-scipy
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: run as root (or install sudo)" >&2; exit 1; }
  sudo="sudo"
fi
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
