#!/usr/bin/env python3
"""Deviation of a DSMC cooling run from Haff's law.

Usage: check_haff.py RUN_DIR [--decades 2]

Reads RUN_DIR/thermo.csv (time, granular_temperature) and
RUN_DIR/summary.json (haff_tau0, haff_initial_temperature) and prints the
largest |T/T_Haff - 1| over the samples down to the first one below
T0 / 10**decades, where
T_Haff = T0 / (1 + t/tau0)**2. Exit status 1 when the run does not cover the
asked decades.
"""
import csv
import json
import sys
from pathlib import Path


def main():
    args = sys.argv[1:]
    if not args:
        sys.exit(__doc__)
    run = Path(args[0])
    decades = float(args[args.index("--decades") + 1]) if "--decades" in args else 2.0
    summary = json.loads((run / "summary.json").read_text())
    tau0 = summary["haff_tau0"]
    t0 = summary["haff_initial_temperature"]
    worst, at, low = 0.0, 0.0, t0
    with open(run / "thermo.csv") as f:
        for row in csv.DictReader(f):
            t = float(row["time"])
            temp = float(row["granular_temperature"])
            low = min(low, temp)
            if temp < t0 / 10**decades:
                break
            dev = temp / (t0 / (1.0 + t / tau0) ** 2) - 1.0
            if abs(dev) > abs(worst):
                worst, at = dev, t / tau0
    covered = t0 / low
    print(
        f"{run}: T fell by a factor {covered:.3g}; over T >= T0/{10**decades:g}: max |T/T_Haff - 1| = "
        f"{abs(worst):.4f} ({worst:+.4f} at t = {at:.3f} tau0)"
    )
    if covered < 10**decades:
        sys.exit(1)


if __name__ == "__main__":
    main()
