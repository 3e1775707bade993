#!/usr/bin/env python3
"""Plot a coarse-grained vertical-stress profile against the weight above.

Usage: python3 tools/plot_fields_profile.py RUN_DIR OUT.png [G [FROM]]

Reads RUN_DIR/fields/fields_00000.csv (a profile along the vertical axis,
`[measure.fields] axes = ["y"]` in 2D or ["z"] in 3D) and draws the total
vertical stress sigma_yy (sigma_zz) against height, with the weight of the
grains above, the integral of rho g from the top down (trapezoids on the
same points; G defaults to 9.81 m/s^2), and the shear stress. Prints the
largest relative gap between the two above the height FROM (m, default 0)
where the weight is over 5 % of its value at the bottom.
"""

import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) not in (3, 4, 5):
        print(__doc__)
        return 2
    run, out = sys.argv[1], sys.argv[2]
    g = float(sys.argv[3]) if len(sys.argv) >= 4 else 9.81
    start = float(sys.argv[4]) if len(sys.argv) == 5 else 0.0
    rows = list(csv.DictReader(open(f"{run}/fields/fields_00000.csv")))
    axis = "z" if "z" in rows[0] else "y"
    h = [float(r[axis]) for r in rows]
    rho = [float(r["density"]) for r in rows]
    s = [float(r[f"stress_{axis}{axis}"]) for r in rows]
    shear = [float(r[f"stress_x{axis}"]) for r in rows]
    weight = [0.0] * len(h)
    for k in range(len(h) - 2, -1, -1):
        weight[k] = weight[k + 1] + g * 0.5 * (rho[k] + rho[k + 1]) * (h[k + 1] - h[k])
    gaps = [
        abs(s[k] - weight[k]) / weight[k]
        for k in range(len(h))
        if h[k] >= start and weight[k] > 0.05 * weight[0]
    ]
    if gaps:
        print(f"{len(gaps)} points above {start} m: worst |sigma - weight| / weight = {max(gaps):.2e}")
    fig, ax = plt.subplots(figsize=(5, 4))
    mm = [x * 1e3 for x in h]
    ax.plot(s, mm, "o", ms=3, label=f"σ_{axis}{axis} (coarse-grained)")
    ax.plot(weight, mm, "-", label="∫ ρ g from the top")
    ax.plot(shear, mm, "--", label=f"σ_x{axis}")
    ax.set_xlabel("stress (N/m in 2D, Pa in 3D)")
    ax.set_ylabel(f"{axis} (mm)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main())
