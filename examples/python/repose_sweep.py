#!/usr/bin/env python3
"""Angle of repose against the friction coefficient: a parameter sweep of
scenarios/repose-2d.toml over contact.mu (and seeds), run with
grains.sweep exactly as `grains sweep` runs it, plotted with matplotlib
beside tan(theta) = mu.

    python examples/python/repose_sweep.py --mu 0.1 0.2 0.3 0.4 --seeds 1 2 --jobs 2

Writes runs/examples/repose-2d-sweep/<variant>/ (each run's files) and
repose_vs_mu.png in the sweep's directory, under the current folder
(--out names another directory).

Needs matplotlib: pip install '.[examples]' from the source tree.
"""

import argparse
import pathlib
import sys
from collections import defaultdict

try:
    import matplotlib
except ImportError:
    sys.exit(
        "This example draws its figure with matplotlib, which `pip install .` does not "
        "bring.\nInstall the examples' extras from the grains source tree:\n\n"
        "    pip install '.[examples]'\n\n(or just: pip install matplotlib)"
    )

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import grains

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mu", type=float, nargs="+", default=[0.1, 0.2, 0.3, 0.4])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default="runs/examples/repose-2d-sweep")
    args = ap.parse_args()

    results = grains.sweep(
        ROOT / "scenarios" / "repose-2d.toml",
        vary={"contact.mu": args.mu, "seed": args.seeds},
        out=args.out,
        jobs=args.jobs,
        quiet=False,
        overwrite=True,  # a rerun replaces the example's own earlier runs
    )
    angles = defaultdict(list)
    for r in results:
        mu = r["values"]["contact.mu"]
        if r["error"]:
            print(f"mu = {mu}, seed {r['values']['seed']}: {r['error']}")
            continue
        a = r["summary"].get("repose_angle_deg")
        if a is None:
            # No slope was fitted: the pile flowed away or stood as a block.
            print(f"mu = {mu}, seed {r['values']['seed']}: no repose angle")
            continue
        angles[mu].append(a)

    mus = sorted(angles)
    mean = np.array([np.mean(angles[m]) for m in mus])
    err = np.array(
        [np.std(angles[m], ddof=1) / np.sqrt(len(angles[m])) if len(angles[m]) > 1 else 0.0 for m in mus]
    )
    for m, a, e in zip(mus, mean, err):
        print(f"mu = {m:.2f}: theta_r = {a:.1f} +- {e:.1f} deg ({len(angles[m])} seeds)")

    fig, ax = plt.subplots(figsize=(5, 4))
    ax.errorbar(mus, mean, yerr=err, marker="o", capsize=3, label="repose-2d (mean over seeds)")
    grid = np.linspace(0.0, max(args.mu), 50)
    ax.plot(grid, np.degrees(np.arctan(grid)), "k--", label=r"$\tan\theta = \mu$")
    ax.set_xlabel(r"friction coefficient $\mu$")
    ax.set_ylabel(r"angle of repose $\theta_r$ (deg)")
    ax.legend()
    fig.tight_layout()
    png = pathlib.Path(args.out) / "repose_vs_mu.png"
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=120)
    print(f"wrote {png.resolve()} (and each run's files in {png.parent.resolve()})")


if __name__ == "__main__":
    main()
