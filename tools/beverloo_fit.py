#!/usr/bin/env python3
"""Fit the Beverloo law W = C (D - k d)^n to a silo sweep.

Reads the sweep.csv written by `grains sweep ... --vary hopper.outlet=...`,
keeps the outlets that did not clog, and fits log W against log(D - k d):
for every k on a fine grid the best C and n are a straight-line fit, and the
k with the smallest residual wins (free fit). The same is done with n held at
the Beverloo value (3/2 in 2D, 5/2 in 3D). Prints both fits with their rms
residuals (in log W) so one can see whether the data tell the exponents
apart, and draws the points with both curves.

usage: beverloo_fit.py SWEEP_CSV --dim 2|3 [--d0 1e-3] [--max-outlet M]
                       [--png out.png]
"""
import argparse
import csv
import sys

import numpy as np


def load(path, max_outlet):
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
        (clogged if r["clogged"] == "1" or w <= 0 else pts).append((d, w))
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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--dim", type=int, choices=[2, 3], required=True)
    ap.add_argument("--d0", type=float, default=1e-3)
    ap.add_argument("--max-outlet", type=float, default=None)
    ap.add_argument("--png")
    a = ap.parse_args()
    pts, clogged = load(a.csv, a.max_outlet)
    if len(pts) < 4:
        sys.exit(f"{a.csv}: {len(pts)} flowing outlets; a free fit needs at least 4")
    D, W = pts[:, 0], pts[:, 1]
    n_bev = 1.5 if a.dim == 2 else 2.5
    free = best(D, W, a.d0)
    fixed = best(D, W, a.d0, n_bev)
    print(f"flowing outlets D/d0: {', '.join(f'{d / a.d0:g}' for d in D)}")
    print(f"clogged outlets D/d0: {', '.join(f'{d / a.d0:g}' for d in clogged) or 'none'}")
    for name, f in [("free", free), (f"n = {n_bev}", fixed)]:
        note = " (k at the edge of its range)" if f["edge"] else ""
        print(f"{name:>8}: n = {f['n']:.2f}, k = {f['k']:.2f}{note}, "
              f"C = {f['C']:.3g}, rms residual in ln W = {f['rms']:.3f}")
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
