#!/usr/bin/env python3
"""Height of the traced grain against time, from a run's tracer.csv.

usage: plot_tracer_height.py RUN_DIR/tracer.csv out.png [--d0 1e-3]
"""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ap = argparse.ArgumentParser()
ap.add_argument("csv")
ap.add_argument("png")
ap.add_argument("--d0", type=float, default=1e-3)
a = ap.parse_args()
lines = [x for x in open(a.csv) if not x.startswith("#")]
names = lines[0].strip().split(",")
d = np.loadtxt(lines[1:], delimiter=",")
# The vertical axis is the last coordinate column (y in 2D, z in 3D).
h = d[:, -1] / a.d0
t = d[:, names.index("time")]
fig, ax = plt.subplots(figsize=(5, 3.5))
ax.plot(t, h, lw=0.6)
ax.set_xlabel("time (s)")
ax.set_ylabel("height of the tracer / d0")
fig.tight_layout()
fig.savefig(a.png, dpi=100)
