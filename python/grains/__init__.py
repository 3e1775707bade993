"""grains: granular dynamics (soft-sphere DEM and DSMC) in 2D and 3D.

Drive a scenario from Python and read its state as numpy arrays::

    import grains
    sim = grains.Simulation("scenarios/pour-3d.toml")
    sim.run(steps=1000)          # progress=True draws a progress bar
    x = sim.positions            # (n, 3) float64, in id order
    print(sim.kinetic_energy, sim.summary()["time"])

`grains.run(path, ...)` runs a scenario exactly as ``grains run`` does
(files and summary.json); `grains.sweep(path, vary={...})` runs a grid of
variants as ``grains sweep`` does. Errors are `grains.InputError` (bad
input: the message names the key or the file), `grains.UnstableError`
(the simulation blew up) and `OSError` (files). See docs/python.md.
"""

from ._native import (
    InputError,
    Scenario,
    Simulation,
    UnstableError,
    __version__,
    run,
    sweep,
)

__all__ = [
    "InputError",
    "Scenario",
    "Simulation",
    "UnstableError",
    "__version__",
    "run",
    "sweep",
]
