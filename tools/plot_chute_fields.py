#!/usr/bin/env python3
"""Plots the chute's coarse-grained profiles (scenarios/chute-fields.toml).

Reads RUN/fields/fields_NNNNN.csv (the last window unless given) and draws
-sigma_xz/sigma_zz against height with tan(theta) (stresses positive in
compression, gravity downhill along +x), and u_x(z) with Bagnold's
u = u_s + A (h^3/2 - (h - z)^3/2) and the best straight line, both fitted
by least squares over the bulk (4 d0 above the base's top and below the
free surface). Prints the figures the docs quote.

    python3 tools/plot_chute_fields.py RUN OUT.png [THETA_DEG] [D0]
"""
import csv
import glob
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

BASE_TOP = 0.00114  # m: the base's mean centre height (0.64 mm) + d0/2


def load(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def main():
    run, out = sys.argv[1], sys.argv[2]
    theta = math.radians(float(sys.argv[3]) if len(sys.argv) > 3 else 24.0)
    d0 = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0e-3
    files = sorted(glob.glob(f"{run}/fields/fields_*.csv"))
    f = load(files[-1])
    z, nu = f["z"], f["packing_fraction"]
    # The free surface: where the packing fraction falls to half its bulk.
    bulk_nu = np.median(nu[(z > BASE_TOP + 4 * d0) & (nu > 0.3)])
    top = z[np.nonzero(nu > 0.5 * bulk_nu)[0].max()]
    h = top - BASE_TOP
    bulk = (z > BASE_TOP + 4 * d0) & (z < top - 4 * d0)
    ratio = -f["stress_xz"] / np.where(f["stress_zz"] > 0, f["stress_zz"], np.nan)
    dev = np.abs(ratio[bulk] / math.tan(theta) - 1.0).max()
    zz = z[bulk] - BASE_TOP
    u = f["vx"][bulk]
    shape = h**1.5 - (h - zz) ** 1.5
    bfit = np.polyfit(shape, u, 1)
    a, slip = bfit
    rms = lambda r: math.sqrt(np.mean(r**2)) / math.sqrt(np.mean(u**2))  # noqa: E731
    bag = rms(u - np.polyval(bfit, shape))
    lin = np.polyfit(zz, u, 1)
    line = rms(u - np.polyval(lin, zz))
    print(f"{files[-1]}: h = {h / d0:.2f} d0, nu_bulk = {bulk_nu:.3f}")
    print(f"max |sxz/szz / tan(theta) - 1| in the bulk: {dev:.4f}")
    print(f"Bagnold A = {a:.4g}, u_s = {slip:.4g}, relative RMS residual {bag:.4f}; line {line:.4f}")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 4.5), sharey=True)
    zs = (z - BASE_TOP) / d0
    keep = (z > BASE_TOP) & (z < top + 2 * d0)
    ax1.plot(ratio[keep], zs[keep], ".", label=r"$-\sigma_{xz}/\sigma_{zz}$")
    ax1.axvline(math.tan(theta), color="k", label=r"$\tan\theta$")
    ax1.axhspan(0, 4, color="0.9")
    ax1.axhspan((top - BASE_TOP) / d0 - 4, h / d0 + 2, color="0.9")
    ax1.set_xlim(0, 1)
    ax1.set_xlabel(r"$-\sigma_{xz}/\sigma_{zz}$")
    ax1.set_ylabel("height above the base / d0")
    ax1.legend()
    ax2.plot(f["vx"][keep], zs[keep], ".", label="coarse-grained $u_x$")
    zf = np.linspace(0, h, 200)
    ax2.plot(slip + a * (h**1.5 - (h - zf) ** 1.5), zf / d0, "k-",
             label=f"Bagnold, RMS {100 * bag:.1f} %")
    ax2.plot(np.polyval(lin, zf), zf / d0, "k:", label=f"line, RMS {100 * line:.1f} %")
    ax2.set_xlabel(r"$u_x$ (m/s)")
    ax2.legend()
    fig.suptitle(f"chute-fields: {math.degrees(theta):.0f}°, h = {h / d0:.1f} d0, w = d0")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
