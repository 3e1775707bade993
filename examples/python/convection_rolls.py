#!/usr/bin/env python3
"""The convection rolls of seed 002 Fig. 2 from the arrays: run
scenarios/seed-convection-modulated.toml (a plate whose amplitude is
largest at mid-width) with grains.Simulation, follow every grain through
the measured cycles, and map the mean displacement on a grid.

    python examples/python/convection_rolls.py --cycles 15

The plate lifts the middle hardest, so grains rise in the middle and sink
at the sides: two counter-rotating rolls. Prints the mean vertical
displacement of the middle and side bands and writes
runs/examples/convection_rolls/convection_rolls.png (under the current
folder; --out names another file).

Needs matplotlib: pip install '.[examples]' from the source tree.
"""

import argparse
import pathlib
import sys

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
FREQUENCY = 70.0  # Hz, the plate's (walls.0.motion.frequency)
SAMPLES_PER_CYCLE = 20


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--relax", type=float, default=10, help="cycles before measuring")
    ap.add_argument("--cycles", type=float, default=15, help="cycles measured")
    ap.add_argument("--out", default="runs/examples/convection_rolls/convection_rolls.png")
    args = ap.parse_args()

    sim = grains.Simulation(ROOT / "scenarios" / "seed-convection-modulated.toml")
    width = 0.02  # the periodic box, domain.hi[0] - domain.lo[0]
    sim.run(time=args.relax / FREQUENCY)

    start = sim.positions
    last = start.copy()
    shift = np.zeros_like(start)
    samples = int(round(args.cycles * SAMPLES_PER_CYCLE))
    for _ in range(samples):
        sim.run(time=1.0 / (FREQUENCY * SAMPLES_PER_CYCLE))
        now = sim.positions
        # Unwrap x across the periodic sides: no grain moves half the box
        # in a twentieth of a cycle.
        jump = now[:, 0] - last[:, 0]
        shift[:, 0] -= width * np.round(jump / width)
        last = now
    moved = (last + shift) - start
    # The bed as a whole drifts (it settles while the rolls turn): the
    # rolls are the displacement relative to the mean.
    moved -= moved.mean(axis=0)

    # Mean displacement per cell of a grid over the starting positions.
    nx, ny = 10, 6
    x0, y0 = start[:, 0] % width, start[:, 1]
    ytop = np.quantile(y0, 0.95)
    ix = np.minimum((x0 / width * nx).astype(int), nx - 1)
    iy = np.minimum((y0 / ytop * ny).astype(int), ny - 1)
    u = np.zeros((ny, nx))
    v = np.zeros((ny, nx))
    count = np.zeros((ny, nx))
    np.add.at(u, (iy, ix), moved[:, 0])
    np.add.at(v, (iy, ix), moved[:, 1])
    np.add.at(count, (iy, ix), 1)
    seen = count > 0
    u[seen] /= count[seen]
    v[seen] /= count[seen]

    middle = np.abs(x0 - width / 2) < 0.2 * width
    sides = np.minimum(x0, width - x0) < 0.2 * width
    rise, sink = moved[middle, 1].mean(), moved[sides, 1].mean()
    print(
        f"after {args.cycles:g} cycles, relative to the bed's mean: "
        f"middle band {1e3 * rise:+.3f} mm, side bands {1e3 * sink:+.3f} mm"
    )
    print("two rolls (up in the middle, down at the sides)" if rise > 0 > sink else "no clear rolls yet")

    fig, ax = plt.subplots(figsize=(6, 4))
    xc = (np.arange(nx) + 0.5) * width / nx
    yc = (np.arange(ny) + 0.5) * ytop / ny
    X, Y = np.meshgrid(xc * 1e3, yc * 1e3)
    ax.scatter(x0 * 1e3, y0 * 1e3, s=4, c="0.8")
    ax.quiver(X[seen], Y[seen], u[seen] * 1e3, v[seen] * 1e3, color="C3", angles="xy")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("height (mm)")
    ax.set_title(f"displacement over {args.cycles:g} cycles, relative to the mean")
    ax.set_aspect("equal")
    fig.tight_layout()
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    print(f"wrote {out.resolve()}")


if __name__ == "__main__":
    main()
