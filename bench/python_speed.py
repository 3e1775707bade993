#!/usr/bin/env python3
"""The speed checks of the Python package (docs/python.md).

1. bench-vib2d.toml for 20 000 steps in one `Simulation.run` call against
   `grains run` of the same scenario and steps, in turns (ROUNDS pairs):
   the seconds of the stepping on both sides (the Python call's wall time;
   the CLI's summary.json wall_seconds, its run loop), each pair's ratio
   Python / CLI and their median.
2. Fetching `positions` of 10^6 grains (3D): the median of REPEAT calls.

    python bench/python_speed.py --grains target/release/grains [--rounds 5] [--threads 1]

Needs the package installed in release mode (`pip install .`) and the
release CLI (`cargo build --release -p grains-cli`).
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import tempfile
import time

import grains

ROOT = pathlib.Path(__file__).resolve().parents[1]
VIB2D = ROOT / "scenarios" / "bench-vib2d.toml"

MILLION = """
name = "python-positions-1e6"
dimension = "3d"
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.106, 0.106, 0.106]
periodic = [true, true, true]
[particles]
placement = "lattice"
count = 1000000
d0 = 1.0e-3
[contact]
preset = "seed"
[run]
dt = 1.0e-6
duration = 1.0e-5
"""


def cli_seconds(binary, steps, threads):
    with tempfile.TemporaryDirectory() as out:
        subprocess.run(
            [binary, "run", str(VIB2D), "--steps", str(steps), "--out", out,
             "--threads", str(threads), "--quiet"],
            check=True,
        )
        return json.loads((pathlib.Path(out) / "summary.json").read_text())["wall_seconds"]


def python_seconds(steps, threads):
    sim = grains.Simulation(VIB2D, threads=threads)
    start = time.perf_counter()
    sim.run(steps=steps)
    return time.perf_counter() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grains", required=True, help="the release CLI binary")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--skip-vib2d", action="store_true")
    args = ap.parse_args()

    if not args.skip_vib2d:
        ratios, ps, cs = [], [], []
        for k in range(args.rounds):
            # Alternate which side goes first.
            if k % 2 == 0:
                c = cli_seconds(args.grains, args.steps, args.threads)
                p = python_seconds(args.steps, args.threads)
            else:
                p = python_seconds(args.steps, args.threads)
                c = cli_seconds(args.grains, args.steps, args.threads)
            ratios.append(p / c)
            ps.append(p)
            cs.append(c)
            print(f"vib2d {args.steps} steps, {args.threads} thread(s): python {p:.3f} s, cli {c:.3f} s, ratio {p / c:.4f}")
        print(f"vib2d median ratio python/cli: {statistics.median(ratios):.4f} over {args.rounds} pairs")
        # On a shared machine the fastest run of each side is the least
        # disturbed one.
        print(f"vib2d fastest: python {min(ps):.3f} s, cli {min(cs):.3f} s, ratio {min(ps) / min(cs):.4f}")

    sim = grains.Simulation(grains.Scenario.from_toml(MILLION))
    assert len(sim) == 1_000_000
    times = []
    for _ in range(args.repeat):
        start = time.perf_counter()
        x = sim.positions
        times.append(time.perf_counter() - start)
    assert x.shape == (1_000_000, 3)
    print(
        f"positions of {len(sim)} grains: median {1e3 * statistics.median(times):.2f} ms, "
        f"min {1e3 * min(times):.2f} ms, max {1e3 * max(times):.2f} ms over {args.repeat} calls"
    )


if __name__ == "__main__":
    main()
