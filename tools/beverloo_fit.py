#!/usr/bin/env python3
"""Fit the Beverloo law W = C (D - k d)^n to a silo sweep.

Reads the sweep.csv written by `grains sweep ... --vary hopper.outlet=...`,
keeps the outlets that did not clog, and fits log W against log(D - k d):
for every k on a fine grid the best C and n are a straight-line fit, and the
k with the smallest residual wins (free fit). The same is done with n held at
the Beverloo value (3/2 in 2D, 5/2 in 3D). Prints both fits with their rms
residuals (in log W) so one can see whether the data tell the exponents
apart, and draws the points with both curves.

With --rho-b (3D): Beverloo's own fit with the exponent 5/2, W^(2/5) a
straight line in D, W^(2/5) = (C rho_b sqrt(g))^(2/5) (D - k d0): C and k
from its slope and intercept, with standard errors from the least-squares
covariance (Beverloo, Leniger & van de Velde 1961); also C with k held at
the literature's 1.5. --square takes the outlet as a square of side L:
Beverloo's W = rho_b A_eff v with the orifice shrunk by an empty band
k d / 2 at its rim and v ~ sqrt(g D_h), D_h = 4 A / P the hydraulic
diameter of the shrunk orifice, gives (L - k d)^2 and D_h = L - k d for
the square against (pi/4) (D - k d)^2 and D - k d for the circle, so
W = (4/pi) C rho_b sqrt(g) (L - k d)^(5/2): the fit with the side, its C
times pi/4, is the circle's C. The circle of equal area, D_eq = 2 L /
sqrt(pi), is printed beside it (it takes sqrt(D_eq), not sqrt(L), as the
velocity scale, and gives a lower C).

With each variant's discharge.csv beside sweep.csv (VARIANT/discharge.csv,
as `grains sweep` writes them), each rate gets a standard error from the
scatter of its rates over --bin (0.1 s) bins after --transient (0.3 s),
and the fits weight the points by it: C and k's errors then come from
those errors (not from the residuals alone), with the fit's chi-square.

--bed DUMP measures rho_b instead from the last snapshot of a LAMMPS dump
of the settled bed (id type radius x y z ...): the mass of the grains
whose centres lie in the central box (2 mm in from the side walls at
x, y in [0, --width], 2 mm above the floor at z = 0 to 2 mm below the
surface, the median top of 2 x 2 mm columns) over its volume, the
grains' density --rho-s.

usage: beverloo_fit.py SWEEP_CSV --dim 2|3 [--d0 1e-3] [--max-outlet M]
                       [--rho-b RHO_B | --bed DUMP [--rho-s 2500] [--width 0.016]]
                       [--square] [--transient 0.3] [--bin 0.1] [--png out.png]
"""
import argparse
import csv
import os
import sys

import numpy as np


def rate_error(path, transient, width):
    """Standard error of the mean rate after `transient` (s): the scatter
    of the rates over bins of `width` (s) of the cumulative mass in the
    discharge.csv at `path`, over the root of their number; None without
    the file or with fewer than three bins."""
    if not os.path.exists(path):
        return None
    a = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if len(a) < 2:
        return None
    t, m = a[:, 0], a[:, 1]
    edges = np.arange(transient, t[-1] + 1e-12, width)
    if len(edges) < 4:
        return None
    rates = np.diff(np.interp(edges, t, m)) / width
    return float(np.std(rates, ddof=1) / np.sqrt(len(rates)))


def load(path, max_outlet, transient=0.3, width=0.1):
    rows = list(csv.DictReader(open(path)))
    if not rows or "hopper.outlet" not in rows[0]:
        sys.exit(f"{path}: no hopper.outlet column (not a silo sweep)")
    pts, clogged = [], []
    for r in rows:
        if r["status"] != "ok":
            continue
        d, w = float(r["hopper.outlet"]), float(r["flow_rate"])
        if max_outlet is not None and d > max_outlet:
            continue
        run = os.path.join(os.path.dirname(path), f"hopper.outlet={r['hopper.outlet']}")
        sw = rate_error(os.path.join(run, "discharge.csv"), transient, width)
        (clogged if r["clogged"] == "1" or w <= 0 else pts).append((d, w, np.nan if sw is None else sw))
    return np.array(sorted(pts)), sorted(c[0] for c in clogged)


def fit_at(D, W, k, d0, n=None):
    """Best (log C, n, rms) for this k; n fixed if given."""
    x = np.log(D - k * d0)
    y = np.log(W)
    if n is None:
        n, lc = np.polyfit(x, y, 1)
    else:
        lc = np.mean(y - n * x)
    res = y - (lc + n * x)
    return lc, n, float(np.sqrt(np.mean(res**2)))


def best(D, W, d0, n=None):
    ks = np.linspace(0.0, D.min() / d0 - 0.05, 2000)
    fits = [(fit_at(D, W, k, d0, n), k) for k in ks]
    (lc, nn, rms), k = min(fits, key=lambda f: f[0][2])
    edge = k == ks[0] or k == ks[-1]
    return dict(k=k, n=nn, C=np.exp(lc), rms=rms, edge=edge)


def beverloo_c_k(D, W, d0, rho_b, g=9.81, sW=None):
    """C and k of W = C rho_b sqrt(g) (D - k d0)^(5/2), with standard errors,
    from the straight line W^(2/5) = a D + b: from the residuals, or with
    the rates' standard errors sW from those (and chi2 of the fit)."""
    y = W ** 0.4
    if sW is None:
        (a, b), cov = np.polyfit(D, y, 1, cov=True)
        chi2 = None
    else:
        sy = 0.4 * y * sW / W
        (a, b), cov = np.polyfit(D, y, 1, w=1.0 / sy, cov="unscaled")
        chi2 = float(np.sum(((y - (a * D + b)) / sy) ** 2))
    k = -b / (a * d0)
    C = a**2.5 / (rho_b * np.sqrt(g))
    dk = np.array([b / (a * a * d0), -1.0 / (a * d0)])  # d k / d (a, b)
    sk = float(np.sqrt(dk @ cov @ dk))
    sC = 2.5 * a**1.5 * np.sqrt(cov[0, 0]) / (rho_b * np.sqrt(g))
    res = y - (a * D + b)
    return dict(C=C, sC=sC, k=k, sk=sk, rms=float(np.sqrt(np.mean(res**2)) / np.mean(y)),
                chi2=chi2)


def c_at_k(D, W, d0, rho_b, k, g=9.81, sW=None):
    """C of W = C rho_b sqrt(g) (D - k d0)^(5/2) with k held, least squares
    in W^(2/5) (a line through (k d0, 0)), with its standard error and the
    rms residual relative to the mean W^(2/5)."""
    x = D - k * d0
    y = W ** 0.4
    wt = np.ones_like(y) if sW is None else 1.0 / (0.4 * y * sW / W) ** 2
    a = float(np.sum(wt * x * y) / np.sum(wt * x * x))
    res = y - a * x
    if sW is None:
        sa = float(np.sqrt(np.sum(res**2) / (len(x) - 1) / np.sum(x * x)))
        chi2 = None
    else:
        sa = float(1.0 / np.sqrt(np.sum(wt * x * x)))
        chi2 = float(np.sum(wt * res**2))
    rms = float(np.sqrt(np.mean(res**2)) / np.mean(y))
    C, sC = a**2.5 / (rho_b * np.sqrt(g)), 2.5 * a**1.5 * sa / (rho_b * np.sqrt(g))
    return C, sC, rms, chi2


def bed_density(path, rho_s, width, margin=2e-3):
    """Bulk density of the central box of the dump's last snapshot."""
    snap = open(path).read().split("ITEM: TIMESTEP")[-1].splitlines()
    head = next(k for k, l in enumerate(snap) if l.startswith("ITEM: ATOMS"))
    cols = snap[head].split()[2:]
    a = np.array([[float(v) for v in l.split()] for l in snap[head + 1:] if l.strip()])
    r, x, y, z = (a[:, cols.index(c)] for c in ("radius", "x", "y", "z"))
    tops = []
    for cx in np.arange(1e-3, width, 2e-3):
        for cy in np.arange(1e-3, width, 2e-3):
            sel = (abs(x - cx) < 1e-3) & (abs(y - cy) < 1e-3)
            if sel.any():
                tops.append((z[sel] + r[sel]).max())
    top = float(np.median(tops))
    lo, hi, zl, zh = margin, width - margin, margin, top - margin
    sel = (x > lo) & (x < hi) & (y > lo) & (y < hi) & (z > zl) & (z < zh)
    mass = rho_s * 4.0 / 3.0 * np.pi * r[sel] ** 3
    rho_b = mass.sum() / ((hi - lo) ** 2 * (zh - zl))
    print(f"bed: surface at {top * 1e3:.2f} mm, {sel.sum()} grains in the central box, "
          f"rho_b = {rho_b:.0f} kg/m^3 (packing {rho_b / rho_s:.3f})")
    return rho_b


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--dim", type=int, choices=[2, 3], required=True)
    ap.add_argument("--d0", type=float, default=1e-3)
    ap.add_argument("--max-outlet", type=float, default=None)
    ap.add_argument("--rho-b", type=float, default=None,
                    help="bulk density of the settled bed (kg/m^3): fit C and k")
    ap.add_argument("--bed", help="LAMMPS dump of the settled bed: measure rho_b")
    ap.add_argument("--rho-s", type=float, default=2500.0)
    ap.add_argument("--width", type=float, default=0.016)
    ap.add_argument("--square", action="store_true",
                    help="outlets are squares of side D: fit D_eq = 2 D / sqrt(pi)")
    ap.add_argument("--transient", type=float, default=0.3,
                    help="start (s) of the steady part that the rate errors read")
    ap.add_argument("--bin", type=float, default=0.1,
                    help="width (s) of the bins whose rates give the errors")
    ap.add_argument("--png")
    a = ap.parse_args()
    pts, clogged = load(a.csv, a.max_outlet, a.transient, a.bin)
    if len(pts) < 4:
        sys.exit(f"{a.csv}: {len(pts)} flowing outlets; a free fit needs at least 4")
    D, W = pts[:, 0], pts[:, 1]
    sW = pts[:, 2] if not np.isnan(pts[:, 2]).any() else None
    if sW is not None:
        print("rate standard errors (%): " + ", ".join(f"{100 * s / w:.1f}" for s, w in zip(sW, W)))
    n_bev = 1.5 if a.dim == 2 else 2.5
    free = best(D, W, a.d0)
    fixed = best(D, W, a.d0, n_bev)
    print(f"flowing outlets D/d0: {', '.join(f'{d / a.d0:g}' for d in D)}")
    print(f"clogged outlets D/d0: {', '.join(f'{d / a.d0:g}' for d in clogged) or 'none'}")
    for name, f in [("free", free), (f"n = {n_bev}", fixed)]:
        note = " (k at the edge of its range)" if f["edge"] else ""
        print(f"{name:>8}: n = {f['n']:.2f}, k = {f['k']:.2f}{note}, "
              f"C = {f['C']:.3g}, rms residual in ln W = {f['rms']:.3f}")
    if a.bed and a.rho_b is None:
        a.rho_b = bed_density(a.bed, a.rho_s, a.width)
    if a.rho_b is not None:
        if a.dim != 3:
            sys.exit("--rho-b: Beverloo's C is the 3D law's")
        # The square's C through the hydraulic diameter is pi/4 of the fit
        # with the side (see the top); the circle's is the fit itself.
        shape = np.pi / 4.0 if a.square else 1.0
        Deq = D * 2.0 / np.sqrt(np.pi) if a.square else D
        bev = beverloo_c_k(D, W, a.d0, a.rho_b, sW=sW)
        bev["C"] *= shape
        bev["sC"] *= shape
        print("| D (mm) | D_eq (mm) | W (g/s) |")
        print("|---|---|---|")
        for d, de, w in zip(D, Deq, W):
            print(f"| {d * 1e3:.2f} | {de * 1e3:.2f} | {w * 1e3:.3f} |")
        print(f"Beverloo (n = 5/2, rho_b = {a.rho_b:.0f} kg/m^3"
              f"{', square through its hydraulic diameter' if a.square else ''}): "
              f"C = {bev['C']:.3f} +- {bev['sC']:.3f}, k = {bev['k']:.2f} +- {bev['sk']:.2f}, "
              f"rms residual of W^(2/5) {100 * bev['rms']:.2f} %"
              + (f", chi2 {bev['chi2']:.2f} for {len(D) - 2} dof" if sW is not None else ""))
        c15, s15, r15, x15 = c_at_k(D, W, a.d0, a.rho_b, 1.5, sW=sW)
        print(f"  with k held at 1.5: C = {c15 * shape:.3f} +- {s15 * shape:.3f}, "
              f"rms residual of W^(2/5) {100 * r15:.2f} %"
              + (f", chi2 {x15:.2f} for {len(D) - 1} dof" if sW is not None else ""))
        if a.square:
            eq = beverloo_c_k(Deq, W, a.d0, a.rho_b, sW=sW)
            print(f"  circle of equal area instead: C = {eq['C']:.3f} +- {eq['sC']:.3f}, "
                  f"k = {eq['k']:.2f} +- {eq['sk']:.2f}")
        if a.png:
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt

            fig, ax = plt.subplots(figsize=(5, 4))
            ax.plot(D / a.d0, W ** 0.4, "o", label="measured")
            x = np.linspace(min(D.min(), (bev["k"] + 0.5) * a.d0), D.max(), 100)
            line = (bev["C"] / shape * a.rho_b * np.sqrt(9.81)) ** 0.4 * (x - bev["k"] * a.d0)
            ax.plot(x / a.d0, line, "-",
                    label=f"C = {bev['C']:.2f} ± {bev['sC']:.2f}, k = {bev['k']:.2f} ± {bev['sk']:.2f}")
            lit = (0.58 / shape * a.rho_b * np.sqrt(9.81)) ** 0.4 * (x - 1.5 * a.d0)
            ax.plot(x / a.d0, lit, "--", label="Beverloo 1961: C = 0.58, k = 1.5")
            ax.set_xlabel("L / d (square of side L)" if a.square else "D / d")
            ax.set_ylabel("W^(2/5) (kg/s)^(2/5)")
            ax.set_title("Beverloo, 3D glass silo")
            ax.legend(fontsize=8)
            fig.tight_layout()
            fig.savefig(a.png, dpi=100)
        return
    if a.png:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 4))
        ax.loglog(D / a.d0, W, "o", label="measured")
        if clogged:
            ax.plot(np.array(clogged) / a.d0, [W.min() / 3] * len(clogged), "x",
                    label="clogged (W = 0)")
        x = np.linspace(D.min(), D.max(), 100)
        for f, style in [(free, "-"), (fixed, "--")]:
            ax.loglog(x / a.d0, f["C"] * (x - f["k"] * a.d0) ** f["n"], style,
                      label=f"n = {f['n']:.2f}, k = {f['k']:.2f}")
        ax.set_xlabel("outlet D / d0")
        ax.set_ylabel("flow rate W (kg/s)")
        ax.set_title(f"Beverloo, {a.dim}D silo")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.png, dpi=100)


if __name__ == "__main__":
    main()
