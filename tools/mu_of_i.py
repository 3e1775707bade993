#!/usr/bin/env python3
"""The μ(I) curve of sheared cells at fixed pressure, fitted and drawn.

Reads run directories (each with summary.json and rheology.csv, as
`grains run` or `grains sweep` write them with `measure.rheology = true`);
a directory without summary.json is searched one level down (a sweep's
output). Per run: μ = <τ>/<P> and I from summary.json, and the error of μ
from 10 block means of rheology.csv (the standard error of the blocks'
μ = Στ/ΣP, which keeps the samples' correlation within a block).

Fits the GDR MiDi (2004) form (Jop, Forterre & Pouliquen 2006 write it so)

    μ(I) = μ_s + (μ_2 − μ_s) / (I_0 / I + 1)

by weighted least squares (Levenberg–Marquardt written out with numpy: no
scipy needed), errors from the covariance (JᵀWJ)⁻¹ scaled by the reduced
χ²; and, for comparison with da Cruz et al. (2005, Phys. Rev. E 72,
021309; 2D disks, μ_p = 0.4: μ ≈ μ_s + b I with μ_s ≈ 0.25, b ≈ 1.1 for
I ≲ 0.3), the straight line μ_s + b I through the points with I below
--linear-max (default 0.3). Prints a table and both fits; with --png
draws the points, the fits and da Cruz et al.'s line, or with
--reference "LABEL:mu_s,mu_2,I_0" (repeatable) published μ(I) curves in
its place (3D cells: Jop, Forterre & Pouliquen 2006's glass beads).

usage: mu_of_i.py RUN_DIR... [--png mu_of_i.png] [--linear-max 0.3]
                  [--json fit.json] [--reference LABEL:MS,M2,I0]...
"""
import argparse
import csv
import glob
import json
import os
import sys

import numpy as np

DA_CRUZ = (0.25, 1.1)  # μ_s, b of da Cruz et al. (2005), 2D, μ_p = 0.4


def runs(paths):
    out = []
    for p in paths:
        if os.path.exists(os.path.join(p, "summary.json")):
            out.append(p)
        else:
            out += sorted(os.path.dirname(s) for s in glob.glob(os.path.join(p, "*", "summary.json")))
    return out


def point(run):
    s = json.load(open(os.path.join(run, "summary.json")))
    if "mu" not in s:
        sys.exit(f"{run}: summary.json has no mu (not a measure.rheology run)")
    rows = list(csv.DictReader(open(os.path.join(run, "rheology.csv"))))
    tau = np.array([float(r["shear_stress"]) for r in rows])
    p = np.array([float(r["pressure"]) for r in rows])
    blocks = [b for b in np.array_split(np.arange(len(rows)), 10) if len(b)]
    mus = np.array([tau[b].sum() / p[b].sum() for b in blocks])
    err = mus.std(ddof=1) / np.sqrt(len(mus)) if len(mus) > 1 else np.nan
    return s["inertial_number"], s["mu"], err, s.get("packing_fraction", np.nan), run


def midi(i, ms, m2, i0):
    return ms + (m2 - ms) / (i0 / i + 1.0)


def fit_midi(i, mu, sd):
    """Weighted Levenberg–Marquardt for (μ_s, μ_2, I_0); errors from the
    covariance scaled by the reduced χ² (when there are spare points)."""
    w = 1.0 / sd**2
    x = np.array([mu.min(), mu.max() + 0.1, np.median(i)])
    lam = 1e-3

    def resid(x):
        return mu - midi(i, *x)

    def jac(x):
        ms, m2, i0 = x
        f = 1.0 / (i0 / i + 1.0)
        return np.column_stack([1.0 - f, f, -(m2 - ms) * f**2 / i])

    chi = np.sum(w * resid(x) ** 2)
    for _ in range(500):
        j, r = jac(x), resid(x)
        a = j.T @ (w[:, None] * j)
        g = j.T @ (w * r)
        step = np.linalg.solve(a + lam * np.diag(np.diag(a)), g)
        trial = x + step
        if trial[2] <= 0:
            lam *= 10
            continue
        c = np.sum(w * resid(trial) ** 2)
        if c < chi:
            x, chi, lam = trial, c, lam / 10
            if np.abs(step).max() < 1e-12:
                break
        else:
            lam *= 10
    j = jac(x)
    cov = np.linalg.inv(j.T @ (w[:, None] * j))
    dof = len(i) - 3
    if dof > 0:
        cov *= chi / dof
    return x, np.sqrt(np.diag(cov)), chi, dof


def fit_line(i, mu, sd):
    w = 1.0 / sd**2
    a = np.column_stack([np.ones_like(i), i])
    cov = np.linalg.inv(a.T @ (w[:, None] * a))
    x = cov @ (a.T @ (w * mu))
    chi = np.sum(w * (mu - a @ x) ** 2)
    dof = len(i) - 2
    if dof > 0:
        cov = cov * chi / dof
    return x, np.sqrt(np.diag(cov))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--png")
    ap.add_argument("--json")
    ap.add_argument("--linear-max", type=float, default=0.3)
    ap.add_argument("--reference", action="append", default=[],
                    help='a published curve "LABEL:mu_s,mu_2,I_0" drawn instead of da Cruz et al.\'s line')
    a = ap.parse_args()
    refs = []
    for r in a.reference:
        label, _, nums = r.rpartition(":")
        try:
            ms, m2, i0 = (float(v) for v in nums.split(","))
        except ValueError:
            sys.exit(f"--reference {r!r}: give LABEL:mu_s,mu_2,I_0 (three numbers)")
        refs.append((label, ms, m2, i0))
    pts = sorted(point(r) for r in runs(a.runs))
    if len(pts) < 3:
        sys.exit(f"{len(pts)} runs: the fit of μ_s, μ_2, I_0 needs at least 3")
    i = np.array([p[0] for p in pts])
    mu = np.array([p[1] for p in pts])
    sd = np.array([p[2] for p in pts])
    # A run too short for blocks gets the largest error seen.
    sd = np.where(np.isfinite(sd) & (sd > 0), sd, np.nanmax(np.where(sd > 0, sd, np.nan)))
    print(f"{'I':>10} {'mu':>8} {'err':>8} {'phi':>7}  run")
    for p in pts:
        print(f"{p[0]:10.4g} {p[1]:8.4f} {p[2]:8.4f} {p[3]:7.4f}  {p[4]}")
    x, e, chi, dof = fit_midi(i, mu, sd)
    print(
        f"GDR MiDi fit: mu_s = {x[0]:.4f} ± {e[0]:.4f}, mu_2 = {x[1]:.4f} ± {e[1]:.4f}, "
        f"I_0 = {x[2]:.4f} ± {e[2]:.4f} (chi2 = {chi:.2f}, {dof} dof)"
    )
    out = {"points": [[p[0], p[1], p[2]] for p in pts], "midi": {"mu_s": [x[0], e[0]], "mu_2": [x[1], e[1]], "I_0": [x[2], e[2]]}}
    lin = i <= a.linear_max
    if lin.sum() >= 3:
        (ms, b), (ems, eb) = fit_line(i[lin], mu[lin], sd[lin])
        print(
            f"linear fit (I <= {a.linear_max}): mu_s = {ms:.4f} ± {ems:.4f}, b = {b:.3f} ± {eb:.3f}; "
            f"da Cruz et al. (2005): mu_s = {DA_CRUZ[0]}, b = {DA_CRUZ[1]}"
        )
        out["linear"] = {"mu_s": [ms, ems], "b": [b, eb], "I_max": a.linear_max}
    if a.json:
        json.dump(out, open(a.json, "w"), indent=1)
    if a.png:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5.5, 4))
        ax.errorbar(i, mu, yerr=sd, fmt="o", color="k", label="runs (block errors)")
        g = np.geomspace(i.min() / 2, i.max() * 2, 200)
        ax.plot(g, midi(g, *x), "-", color="C0",
                label=f"GDR MiDi fit: μ_s={x[0]:.3f}, μ_2={x[1]:.3f}, I_0={x[2]:.3f}")
        for k, (label, ms, m2, i0) in enumerate(refs):
            ax.plot(g, midi(g, ms, m2, i0), "--", color=f"C{k + 3}",
                    label=f"{label}: μ_s={ms:g}, μ_2={m2:g}, I_0={i0:g}")
        if not refs:
            gl = g[g <= 0.3]
            ax.plot(gl, DA_CRUZ[0] + DA_CRUZ[1] * gl, "--", color="C3",
                    label="da Cruz et al. 2005: 0.25 + 1.1 I")
        ax.set_xscale("log")
        ax.set_xlabel("inertial number I")
        ax.set_ylabel("μ = τ / P")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(a.png, dpi=120)
        print(f"wrote {a.png}")


if __name__ == "__main__":
    main()
