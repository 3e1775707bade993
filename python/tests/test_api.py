"""Shapes, ids, dtypes and errors of the Python API."""

import numpy as np
import pytest

import grains


def test_arrays_have_the_documented_shapes_2d(scenarios):
    sim = grains.Simulation(scenarios / "seed-convection-modulated.toml")
    n = len(sim)
    assert n == 200 and sim.dimension == 2 and sim.method == "md"
    assert sim.ids.dtype == np.int64 and np.array_equal(sim.ids, np.arange(1, n + 1))
    for name in ["positions", "velocities"]:
        a = getattr(sim, name)
        assert a.shape == (n, 2) and a.dtype == np.float64, name
    assert sim.angular_velocities.shape == (n,)
    assert sim.diameters.shape == (n,) and sim.masses.shape == (n,)
    assert sim.frozen.dtype == np.bool_ and sim.frozen.shape == (n,)
    # diameters in [0.75, 1.25] mm (particles.width = 0.5), masses of steel spheres
    d = sim.diameters
    assert d.min() >= 0.75e-3 and d.max() <= 1.25e-3
    np.testing.assert_allclose(sim.masses, 7850.0 * np.pi / 6.0 * d**3, rtol=1e-12)
    # A copy: writing it changes nothing in the engine.
    p = sim.positions
    p[:] = 0.0
    assert sim.positions.any()


def test_arrays_3d_and_state(scenarios):
    sim = grains.Simulation(scenarios / "pour-3d.toml", threads=2)
    n = len(sim)
    assert sim.dimension == 3
    assert sim.positions.shape == (n, 3)
    assert sim.angular_velocities.shape == (n, 3)
    sim.run(steps=50)
    assert sim.step == 50
    assert sim.time == pytest.approx(50 * sim.dt, rel=1e-12)
    # Kinetic energy from the arrays.
    ke = 0.5 * np.sum(sim.masses[:, None] * sim.velocities**2)
    assert sim.kinetic_energy == pytest.approx(ke, rel=1e-12)
    sim.run(time=10 * sim.dt)
    assert sim.step == 60


def test_summary_has_the_summary_json_keys(scenarios, tmp_path):
    path = scenarios / "seed-convection-modulated.toml"
    ran = grains.run(path, out=tmp_path, steps=20)
    sim = grains.Simulation(path)
    sim.run(steps=20)
    mine = sim.summary()
    # Every key but the runner's measurements (convection, displacement).
    measured = {"convection_center_vz", "convection_edge_vz", "convection_strength",
                "heap_height", "tracer_rms", "transport_velocity"}
    assert set(ran) - measured == set(mine)
    for k in ["kinetic_energy", "particles", "steps", "time", "dt", "neighbor_builds"]:
        assert mine[k] == ran[k], k


def test_thermo_is_a_table(scenarios):
    sim = grains.Simulation(scenarios / "bench-vib2d.toml")
    sim.run(steps=120)
    t = sim.thermo
    assert list(t["step"]) == [0.0, 120.0]
    assert list(t.keys()) == ["step", "time", "kinetic_energy", "rotational_energy",
                              "granular_temperature", "contacts", "max_overlap"]


def test_bad_keys_raise_input_error_naming_them(scenarios, tmp_path):
    path = scenarios / "seed-convection-modulated.toml"
    s = grains.Scenario.load(path)
    with pytest.raises(grains.InputError, match="mux"):
        s.set("contact.mux", 0.3)
    # The scenario is unchanged after a refused set.
    assert s.overrides == []
    with pytest.raises(grains.InputError, match="integrator"):
        s.set("run.integrator", "leapfrog")
    with pytest.raises(grains.InputError, match="walls.7"):
        s.set("walls.7.motion.frequency", 60)
    with pytest.raises(grains.InputError, match="bogus"):
        grains.run(path, out=tmp_path, steps=1, set={"bogus.key": 1})
    with pytest.raises(grains.InputError, match="steps"):
        grains.run(path, out=tmp_path, steps=0)
    s.set("contact.mu", 0.3)
    assert "mu = 0.3" in s.to_toml()
    assert s.overrides == ["contact.mu=0.3"]


def test_files_and_types(scenarios, tmp_path):
    with pytest.raises(FileNotFoundError):
        grains.Simulation(tmp_path / "missing.toml")
    with pytest.raises(TypeError):
        grains.Simulation(42)
    bad = tmp_path / "bad.toml"
    bad.write_text("name = 'x'\n[contact]\nkn = 'stiff'\n")
    with pytest.raises(grains.InputError, match="bad.toml"):
        grains.Scenario.load(bad)
    with pytest.raises(grains.InputError, match="hopper"):
        grains.Simulation(scenarios / "hopper-2d.toml")


def test_setters_check_shapes_and_values(scenarios):
    sim = grains.Simulation(scenarios / "seed-convection-modulated.toml")
    with pytest.raises(grains.InputError, match=r"\(200, 2\)"):
        sim.positions = np.zeros((199, 2))
    p = sim.positions
    p[3, 1] = np.nan
    with pytest.raises(grains.InputError, match="row 3"):
        sim.positions = p
    with pytest.raises(grains.InputError, match="not an array"):
        sim.velocities = "fast"
    with pytest.raises(grains.InputError, match="both"):
        sim.run(steps=1, time=1.0)
    with pytest.raises(grains.InputError):
        sim.run(steps=-1)


def test_dsmc_arrays(scenarios):
    sim = grains.Simulation(scenarios / "gas-vibrated-3d.toml")
    n = len(sim)
    assert sim.positions.shape == (n, 3)
    assert np.array_equal(sim.ids, np.arange(1, n + 1))
    with pytest.raises(grains.InputError, match="DSMC"):
        sim.contacts()
    v = sim.velocities * 2.0
    sim.velocities = v
    assert sim.kinetic_energy == pytest.approx(0.5 * np.sum(sim.masses[:, None] * v**2), rel=1e-12)


def test_unstable_raises(scenarios):
    # Contacts so soft that the grains pass halfway through each other.
    s = grains.Scenario.load(scenarios / "two-particle-collision.toml")
    s.set("contact.kn", 0.01).set("run.dt", 1e-5)
    sim = grains.Simulation(s)
    with pytest.raises(grains.UnstableError, match="overlaps grain"):
        sim.run(steps=1000)


def test_help_reads():
    text = grains.Simulation.__doc__ + grains.Simulation.positions.__doc__
    assert "id order" in text
    assert "KEY=VALUE" in grains.Scenario.overrides.__doc__
    assert grains.__doc__.startswith("grains: granular dynamics")
    assert issubclass(grains.InputError, ValueError)
    assert issubclass(grains.UnstableError, RuntimeError)
