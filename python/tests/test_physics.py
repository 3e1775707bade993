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


def test_sweep_over_restitution(scenarios, tmp_path):
    """grains.sweep runs each variant as `grains sweep` does; the head-on
    collision keeps e^2 of its kinetic energy for each restitution e
    (contact.restitution sets gamma_n from the closed form)."""
    path = scenarios / "two-particle-collision.toml"
    e0 = grains.Simulation(path).kinetic_energy
    results = grains.sweep(path, vary={"contact.restitution": [0.5, 0.8]}, out=tmp_path, jobs=2)
    assert [r["values"]["contact.restitution"] for r in results] == [0.5, 0.8]
    for r in results:
        assert r["error"] is None
        assert (r["dir"] / "summary.json").is_file()
        e = r["values"]["contact.restitution"]
        # The dashpot acts on half-step velocities: a first-order error in
        # dt / t_c = 1/50 on e.
        assert np.sqrt(r["summary"]["kinetic_energy"] / e0) == pytest.approx(e, rel=0.02)
    # A bad key fails before any run; a bad value fails its variant only.
    with pytest.raises(grains.InputError, match="restitutio"):
        grains.sweep(path, vary={"contact.restitutio": [0.5]}, out=tmp_path)
    # The first sweep's runs are in tmp_path: replaced, not mixed.
    bad = grains.sweep(path, vary={"contact.restitution": [0.5, 2.0]}, out=tmp_path, overwrite=True)
    assert bad[0]["error"] is None and bad[1]["summary"] is None
    assert "contact.restitution = 2" in bad[1]["error"]
