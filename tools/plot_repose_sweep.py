#!/usr/bin/env python3
"""θ_r against μ from repose sweeps (one or more sweep.csv files, each a grid
of contact.mu × seed), averaged over seeds, beside tan θ = μ.

usage: plot_repose_sweep.py out.png LABEL=SWEEP_CSV [LABEL=SWEEP_CSV ...]

Runs without a fitted slope (no repose_angle_deg) are counted apart: the
pile either flowed away entirely (few remaining grains: counted as 0°) or
stood as a block (most grains stayed: left out of the mean and reported).
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def table(path):
    rows = [r for r in csv.DictReader(open(path)) if r["status"] == "ok"]
    by_mu = defaultdict(list)
    for r in rows:
        n = float(r["particles"])
        left = float(r["remaining_grains"])
        a = r.get("repose_angle_deg", "")
        if a not in ("", None):
            by_mu[float(r["contact.mu"])].append(float(a))
        elif left < 0.1 * n:  # all but a few flowed away: flat
            by_mu[float(r["contact.mu"])].append(0.0)
        else:
            by_mu[float(r["contact.mu"])].append(None)  # standing block
    return dict(sorted(by_mu.items()))


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out = sys.argv[1]
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for arg in sys.argv[2:]:
        label, path = arg.split("=", 1)
        t = table(path)
        mus, means, sds, odd = [], [], [], []
        print(f"{label}: mu, runs (deg; None = no avalanche), mean +- sd")
        for mu, vals in t.items():
            ok = [v for v in vals if v is not None]
            print(f"  {mu:g}: {[None if v is None else round(v, 1) for v in vals]}"
                  + (f" -> {np.mean(ok):.1f} +- {np.std(ok):.1f}" if ok else ""))
            if ok and len(ok) == len(vals):
                mus.append(mu)
                means.append(np.mean(ok))
                sds.append(np.std(ok))
            else:  # some seeds stood as a block: show the others one by one
                odd += [(mu, v) for v in ok]
        line = ax.errorbar(mus, means, yerr=sds, marker="o", capsize=3, label=label)
        if odd:
            ax.plot(*zip(*odd), "x", color=line[0].get_color(),
                    label=f"{label}: single runs where other seeds stood")
    m = np.linspace(0, 1, 100)
    ax.plot(m, np.degrees(np.arctan(m)), "k--", label="tan θ = μ")
    ax.axhline(45, color="grey", lw=0.5)
    ax.set_xlabel("friction coefficient μ")
    ax.set_ylabel("angle of repose θ_r (deg)")
    ax.legend(fontsize=8, loc="center right")
    fig.tight_layout()
    fig.savefig(out, dpi=100)


if __name__ == "__main__":
    main()
