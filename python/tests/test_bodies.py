"""Rigid clumps from Python: orientations and angular momenta per body."""

import numpy as np

import grains

# One dimer of two touching spheres (radius r, along x as written) spinning
# in free space: no gravity, no walls, nothing to touch.
DIMER = """
name = "spinning-dimer"
dimension = "3d"
gravity = [0.0, 0.0, 0.0]

[domain]
lo = [-0.01, -0.01, -0.01]
hi = [0.01, 0.01, 0.01]

[particles]
placement = "none"
d0 = 1.0e-3

[[particles.add]]
shape = "dimer"
position = [0.0, 0.0, 0.0]
orientation = [1.0, 0.0, 0.0, 0.0]
omega = [30.0, 0.0, 20.0]

[contact]
preset = "lammps-hooke-history"

[run]
integrator = "verlet"
dt = 1.0e-6
duration = 1.0e-3

[[shapes]]
name = "dimer"
units = "d0"
spheres = [{ center = [-0.5, 0.0, 0.0], radius = 0.5 }, { center = [0.5, 0.0, 0.0], radius = 0.5 }]
"""


def test_a_spinning_dimer_has_the_angular_momentum_of_its_inertia():
    sim = grains.Simulation(grains.Scenario.from_toml(DIMER))
    assert len(sim) == 2
    q = sim.orientations
    assert q.shape == (1, 4) and q.dtype == np.float64
    assert abs(np.linalg.norm(q[0]) - 1.0) < 1e-15
    # Closed form: about the axis each sphere gives (2/5) m r^2; about a
    # perpendicular axis through the contact point (2/5) m r^2 + m r^2
    # (parallel axes, each centre r away). The sphere's mass and radius
    # are those the engine gives its sub-spheres.
    m = sim.masses[0]
    r = sim.diameters[0] / 2.0
    i_axis = 2.0 * 0.4 * m * r * r
    i_perp = 2.0 * (0.4 + 1.0) * m * r * r
    want = np.array([i_axis * 30.0, 0.0, i_perp * 20.0])
    L0 = sim.angular_momenta
    assert L0.shape == (1, 3)
    np.testing.assert_allclose(L0[0], want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
    # Torque-free: L stays in space while the body turns (NO_SQUISH keeps
    # it to rounding; docs/clumps-engine.md), and the quaternion moves.
    sim.run(steps=1000)
    np.testing.assert_allclose(sim.angular_momenta[0], want, rtol=1e-10, atol=1e-10 * np.abs(want).max())
    assert abs(np.linalg.norm(sim.orientations[0]) - 1.0) < 1e-14
    assert np.abs(sim.orientations[0] - q[0]).max() > 1e-3


def test_spheres_alone_have_no_bodies(scenarios):
    sim = grains.Simulation(scenarios / "pour-3d.toml")
    assert sim.orientations.shape == (0, 4)
    assert sim.angular_momenta.shape == (0, 3)
