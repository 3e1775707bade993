#!/usr/bin/env python3
"""Seed 002 ensembles: frequencies and mean strengths from the sweeps.

Reads DIR/<setting>/sweep.csv as written by tools/seed002_ensembles.sh and
prints one markdown row per setting: runs (finished / started), the mean
convection strength (centre minus edge mean vertical velocity) with its
standard error, how often each claim's sign shows, as k/n with a 95 %
Wilson interval, heap_height, and how far the median grain travelled over
the measured cycles (from each run's displacement.csv). Standard library
only.

    python3 tools/seed002_table.py runs/seed002-ensembles [SETTING ...]
    python3 tools/seed002_table.py runs/seed002-ensembles --ratio A B [--ratio C D ...]

With --ratio, prints instead the ratio of the mean strengths of settings
A and B with its propagated standard error, and Welch's t of their
difference (the verdicts' "γ × 10" and "γ_s = 0" comparisons).
"""

import csv
import math
import statistics
import sys
from pathlib import Path


def wilson(k, n, z=1.96):
    """95 % Wilson score interval of a binomial frequency k/n."""
    if n == 0:
        return (float("nan"), float("nan"))
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (max(0.0, c - h), min(1.0, c + h))


def mean_se(xs):
    if not xs:
        return (float("nan"), float("nan"))
    m = statistics.fmean(xs)
    se = statistics.stdev(xs) / math.sqrt(len(xs)) if len(xs) > 1 else float("nan")
    return (m, se)


def load(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    ok = [r for r in rows if r["status"] == "ok"]
    return rows, ok


def freq(k, n):
    lo, hi = wilson(k, n)
    return f"{k}/{n} [{lo:.2f}, {hi:.2f}]"


def travel(run_dir):
    """Median over the grains of the distance each moved over the measured
    cycles (mm), from the run's displacement.csv (unwrapped positions)."""
    path = run_dir / "displacement.csv"
    if not path.exists():
        return None
    with open(path, newline="") as f:
        d = [
            math.hypot(float(r["x1"]) - float(r["x0"]), float(r["y1"]) - float(r["y0"]))
            for r in csv.DictReader(f)
        ]
    return 1e3 * statistics.median(d) if d else None


def row(name, rows, ok, sweep):
    c = [float(r["convection_center_vz"]) for r in ok]
    e = [float(r["convection_edge_vz"]) for r in ok]
    s = [float(r["convection_strength"]) for r in ok]
    # heap_height is left out of summary.json when it is not a number.
    h = [float(r["heap_height"]) * 1e3 for r in ok if r.get("heap_height") not in (None, "")]
    n = len(ok)
    sm, sse = mean_se(s)
    cm, cse = mean_se(c)
    em, ese = mean_se(e)
    hm, hse = mean_se(h)
    up_centre = sum(1 for a, b in zip(c, e) if a > 0 > b)
    up_walls = sum(1 for a, b in zip(c, e) if b > a)
    drag = sum(1 for a, b in zip(c, e) if b < 0 and b < a)
    heap = sum(1 for x in h if x > 0)
    nh = len(h)
    moved = [t for t in (travel(sweep / f"seed={r['seed']}") for r in ok) if t is not None]
    tm, tse = mean_se(moved)
    return (
        f"| {name} | {n}/{len(rows)} | {1e3 * sm:+.1f} ± {1e3 * sse:.1f} "
        f"| {1e3 * cm:+.1f} ± {1e3 * cse:.1f} | {1e3 * em:+.1f} ± {1e3 * ese:.1f} "
        f"| {freq(up_centre, n)} | {freq(up_walls, n)} | {freq(drag, n)} "
        f"| {hm:+.2f} ± {hse:.2f} | {freq(heap, nh)} | {tm:.1f} ± {tse:.1f} |"
    )


def strengths(root, name):
    _, ok = load(root / name / "sweep.csv")
    return [1e3 * float(r["convection_strength"]) for r in ok]


def ratio_line(root, a, b):
    """Strength of A over that of B, error propagated from the two
    standard errors (independent ensembles), and Welch's t of A - B."""
    (am, ase), (bm, bse) = mean_se(strengths(root, a)), mean_se(strengths(root, b))
    r = am / bm
    rse = abs(r) * math.hypot(ase / am, bse / bm)
    t = (am - bm) / math.hypot(ase, bse)
    return f"{a} / {b}: {am:.1f} ± {ase:.1f} / {bm:.1f} ± {bse:.1f} = {r:.2f} ± {rse:.2f} (Welch t = {t:+.1f})"


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else "runs/seed002-ensembles")
    args = sys.argv[2:]
    if "--ratio" in args:
        while args:
            if args[0] != "--ratio" or len(args) < 3:
                sys.exit("usage: seed002_table.py DIR --ratio A B [--ratio C D ...]")
            print(ratio_line(root, args[1], args[2]))
            args = args[3:]
        return
    names = args or sorted(p.name for p in root.iterdir() if (p / "sweep.csv").exists())
    print(
        "| setting | runs | strength (mm/s) | centre v_z (mm/s) | edge v_z (mm/s) "
        "| up in centre, down at edges | edge above centre (up at walls) "
        "| down at edges, below centre | heap_height (mm) | heap > 0 "
        "| median travel (mm) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in names:
        path = root / name / "sweep.csv"
        if not path.exists():
            print(f"| {name} | (not run) ||||||||||")
            continue
        rows, ok = load(path)
        print(row(name, rows, ok, root / name))


if __name__ == "__main__":
    main()
