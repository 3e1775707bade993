"""Setters mid-run carry the stretched springs: the contact forces of a
settled bed (Hertz-Mindlin with epsd rolling springs; JKR adhesion with
constant rolling torque) are the same right after the positions and
velocities are set to themselves, the Cundall-Strack spring included."""

import numpy as np
import pytest

import grains


def settled(scenarios, extra):
    s = grains.Scenario.load(scenarios / "pour-3d-sand.toml")
    sets = [
        ("particles.count", 200),
        ("particles.region.lo", [0.0, 0.0, 0.0006]),
        ("particles.region.hi", [0.012, 0.012, 0.005]),
    ] + extra
    for k, v in sets:
        s = s.set(k, v)
    sim = grains.Simulation(s, threads=1)
    sim.run(steps=30000)  # about 62 ms: the grains rest on the floor
    return sim


def forces(sim):
    """Contact forces by id pair (smaller id first, force on it)."""
    c = sim.contacts()
    out = {}
    for (i, j), f, n in zip(c["ids"], c["force"], c["normal"]):
        key, sign = ((i, j), 1.0) if i < j else ((j, i), -1.0)
        out[key] = (sign * f, sign * n)
    return out


JKR = [
    ("contact.rolling", "constant"),
    ("contact.cohesion", "jkr"),
    ("materials.0.surface_energy", 0.05),
    ("materials.1.surface_energy", 0.05),
]


@pytest.mark.parametrize("extra", [[], JKR], ids=["epsd", "jkr"])
def test_setters_keep_the_stretched_springs(scenarios, extra):
    sim = settled(scenarios, extra)
    before = forces(sim)
    assert len(before) >= 4, "the bed has grain-grain contacts"
    # The tangential part (the Cundall-Strack spring and dashpot) is there:
    # dropping the springs would change these forces.
    tangential = [np.linalg.norm(f - np.dot(f, n) * n) for f, n in before.values()]
    assert max(tangential) > 1e-3 * max(np.linalg.norm(f) for f, _ in before.values())
    sim.positions = sim.positions
    sim.velocities = sim.velocities
    after = forces(sim)
    assert after.keys() == before.keys()
    for k in before:
        np.testing.assert_allclose(after[k][0], before[k][0], rtol=1e-9, atol=1e-15, err_msg=str(k))
    sim.run(steps=1000)
    assert np.all(np.isfinite(sim.positions))
