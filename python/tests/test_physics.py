"""Physics read through the arrays, against closed forms."""

import numpy as np
import pytest

import grains


def test_head_on_collision_keeps_restitution_squared(scenarios):
    """Two disks meet head-on with contact.restitution = 0.8: the kinetic
    energy after the collision is e^2 = 0.64 of the one before. The linear
    spring-dashpot gives e exactly in continuous time; dt = t_c/50 of the
    velocity-Verlet scheme shifts it by well under 1 %."""
    sim = grains.Simulation(scenarios / "two-particle-collision.toml")
    e0 = sim.kinetic_energy
    sim.run()
    assert sim.kinetic_energy / e0 == pytest.approx(0.64, rel=0.01)
    # Momentum is conserved to rounding: equal masses, opposite velocities.
    p = np.sum(sim.masses[:, None] * sim.velocities, axis=0)
    assert np.abs(p).max() < 1e-15


def test_contact_force_is_the_elastic_law(scenarios):
    """Two disks at rest pressed by xi: contacts() gives k_n xi (beta = 1)
    along the line of centres."""
    sim = grains.Simulation(scenarios / "two-particle-collision.toml")
    xi = 2.0e-5
    pos = np.array([[0.004, 0.002], [0.005 - xi, 0.002]])
    sim.positions = pos
    sim.velocities = np.zeros((2, 2))
    c = sim.contacts()
    assert c["ids"].tolist() in ([[1, 2]], [[2, 1]])
    assert c["overlap"][0] == pytest.approx(xi, rel=1e-9)
    f = c["force"][0]
    assert np.linalg.norm(f) == pytest.approx(1000.0 * xi, rel=1e-9)
    first = c["ids"][0, 0]
    # The force pushes the first grain away from the second.
    assert np.sign(f[0]) == (-1.0 if first == 1 else 1.0)
    assert abs(f[1]) < 1e-15
