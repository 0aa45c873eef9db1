#!/usr/bin/env python3
"""A simulated run's wall forces as the apparatus' readings a lab's load cell would give,
cycle by cycle (the CSV `granmem track/link/import --readings` take): for scans drawn from
a pseudo-experiment (docs/CALIBRATION.md, "The wall's force read beside the scans").
Usage: scripts/apparatus_readings_of_run.py RUN.h5 > readings.csv"""
import sys
import h5py

with h5py.File(sys.argv[1], "r") as f:
    full = f["/observables/wall_force_full_compression"]
    unloaded = f["/observables/wall_force"]
    steps = list(full["step"][...])
    if list(unloaded["step"][...]) != steps:
        sys.exit(f"{sys.argv[1]}: the two wall forces are read at different cycles")
    print(f"# the wall's force of {sys.argv[1]}, N")
    print("cycle,wall_force_full_compression,wall_force_unloaded")
    for c, a, b in zip(steps, full["value"][...], unloaded["value"][...]):
        print(f"{c},{a!r},{b!r}")
