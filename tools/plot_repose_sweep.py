#!/usr/bin/env python3
"""θ_r against μ from repose sweeps (one or more sweep.csv files, each a grid
of contact.mu × seed), averaged over seeds, beside tan θ = μ.

usage: plot_repose_sweep.py out.png LABEL=SWEEP_CSV [LABEL=SWEEP_CSV ...]

Runs without a fitted slope (no repose_angle_deg) are counted apart: the
pile either flowed away entirely (few remaining grains: counted as 0°) or
stood as a block (most grains stayed: left out of the mean, drawn as a
marker on the top edge with the number of seeds that stood).
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
    fig, ax = plt.subplots(figsize=(6, 5.2))
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
        color = line[0].get_color()
        if odd:
            ax.plot(*zip(*odd), "x", color=color,
                    label=f"{label}: single runs where other seeds stood")
        # Runs with no avalanche at all: a marker on the top edge, with the
        # count of seeds whose pile stood as a block.
        stood = [(mu, sum(v is None for v in vals), len(vals))
                 for mu, vals in t.items() if any(v is None for v in vals)]
        if stood:
            top = 68.0
            ax.plot([s[0] for s in stood], [top] * len(stood), "^", color=color,
                    label=f"{label}: pile stood as a block (seeds shown)")
            for mu, k, n in stood:
                ax.annotate(f"{k}/{n}", (mu, top), textcoords="offset points",
                            xytext=(0, -12), ha="center", fontsize=7, color=color)
    m = np.linspace(0, 1, 100)
    ax.plot(m, np.degrees(np.arctan(m)), "k--", label="tan θ = μ")
    ax.axhline(45, color="grey", lw=0.5)
    ax.set_xlabel("friction coefficient μ")
    ax.set_ylabel("angle of repose θ_r (deg)")
    ax.set_ylim(-2, 72)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)
    fig.tight_layout()
    fig.savefig(out, dpi=100)


if __name__ == "__main__":
    main()
