#!/usr/bin/env python3
"""Seed 002: the time-averaged flow field averaged again over an ensemble.

Reads SWEEP/seed=*/flow_field.csv (written by `measure.flow_field` in each
run of a `grains sweep ... --vary seed=...`, e.g. tools/seed002_ensembles.sh),
averages each cell's mean velocity over the runs, weighting each run by the
grain samples it had in the cell, and draws the arrows over the mean packing
fraction. Arrows are drawn where the
mean packing fraction is at least 0.2. Rolls of a few mm/s, buried in one run's noise, show in the mean
of twenty. Needs numpy and matplotlib.

    python3 tools/plot_seed002_flow.py runs/seed002-ensembles/w-today-gs0 out.png [title]
"""

import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    sweep, out = Path(sys.argv[1]), sys.argv[2]
    title = sys.argv[3] if len(sys.argv) > 3 else sweep.name
    files = sorted(sweep.glob("seed=*/flow_field.csv"))
    if not files:
        sys.exit(f"{sweep}: no seed=*/flow_field.csv (run the sweep with measure.flow_field)")
    cells = {}
    for f in files:
        for r in read(f):
            key = (int(r["ix"]), int(r["iy"]))
            c = cells.setdefault(key, [float(r["x"]), float(r["y"]), 0.0, 0.0, 0.0, 0.0, 0])
            w = float(r["grain_samples"])
            if w > 0:
                c[2] += w * float(r["vx"])
                c[3] += w * float(r["vy"])
                c[4] += w
            c[5] += float(r["packing_fraction"])
            c[6] += 1
    nx = 1 + max(k[0] for k in cells)
    ny = 1 + max(k[1] for k in cells)
    x = np.zeros((ny, nx))
    y = np.zeros((ny, nx))
    u = np.zeros((ny, nx))
    v = np.zeros((ny, nx))
    phi = np.zeros((ny, nx))
    for (i, j), c in cells.items():
        x[j, i], y[j, i] = c[0] * 1e3, c[1] * 1e3
        if c[4] > 0:
            u[j, i], v[j, i] = c[2] / c[4] * 1e3, c[3] / c[4] * 1e3
        phi[j, i] = c[5] / c[6]
    dx = x[0, 1] - x[0, 0] if nx > 1 else 1.0
    dy = y[1, 0] - y[0, 0] if ny > 1 else 1.0
    fig, ax = plt.subplots(figsize=(5.0, 5.0 * ny * dy / (nx * dx) + 0.6))
    ax.imshow(
        phi,
        origin="lower",
        extent=(x.min() - dx / 2, x.max() + dx / 2, y.min() - dy / 2, y.max() + dy / 2),
        cmap="viridis",
        vmin=0,
        alpha=0.55,
    )
    # Arrows only where the bed is (mean packing at least 0.2): the few
    # grains thrown below the plate's rest line or above the surface move
    # fast and would set the scale.
    bed = phi >= 0.2
    u, v = np.where(bed, u, 0.0), np.where(bed, v, 0.0)
    speed = np.hypot(u, v).max()
    q = ax.quiver(x, y, u, v, angles="xy", scale_units="xy", scale=speed / (0.9 * dx), width=0.006)
    ax.quiverkey(q, 0.72, -0.16, speed, f"{speed:.1f} mm/s", labelpos="E")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("height (mm)")
    ax.set_title(f"{title}: mean of {len(files)} runs", fontsize=9, loc="left")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
