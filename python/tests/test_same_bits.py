"""A scenario driven from Python gives the bits of `grains run`."""

import json
import pathlib
import subprocess

import numpy as np
import pytest

import grains
from conftest import read_dump_last, read_thermo

STEPS = 300


def final_state(run_dir):
    """Positions and velocities (id order) of the last dump frame."""
    rows = read_dump_last(pathlib.Path(run_dir) / "dump.lammpstrj")
    ids = sorted(rows)
    a = np.array([rows[i] for i in ids])
    return np.array(ids), a[:, :3], a[:, 3:]


def check_same(sim, run_dir):
    summary = json.loads((pathlib.Path(run_dir) / "summary.json").read_text())
    assert sim.step == summary["steps"] == STEPS
    # Bit for bit: the JSON and the dump carry round-trip decimals.
    assert sim.kinetic_energy == summary["kinetic_energy"]
    assert sim.rotational_energy == summary["rotational_energy"]
    assert sim.granular_temperature == summary["granular_temperature"]
    ids, pos, vel = final_state(run_dir)
    d = sim.dimension
    assert np.array_equal(sim.ids, ids)
    assert np.array_equal(sim.positions, pos[:, :d])
    assert np.array_equal(sim.velocities, vel[:, :d])
    # The thermo table has the rows (and bits) of thermo.csv.
    csv = read_thermo(pathlib.Path(run_dir) / "thermo.csv")
    table = sim.thermo
    for col in csv:
        assert np.array_equal(np.asarray(table[col], dtype=float), np.array(csv[col])), col


@pytest.mark.parametrize(
    "name", ["seed-convection-modulated.toml", "pour-3d.toml", "bench-vib2d.toml"]
)
def test_simulation_matches_grains_run_from_python(scenarios, tmp_path, name):
    path = scenarios / name
    grains.run(path, out=tmp_path, steps=STEPS, set={"output.dump": True}, threads=2)
    sim = grains.Simulation(grains.Scenario.load(path).set("output.dump", True), threads=1)
    sim.run(steps=STEPS)
    check_same(sim, tmp_path)


def test_simulation_matches_the_cli(scenarios, tmp_path, grains_bin):
    path = scenarios / "seed-convection-modulated.toml"
    subprocess.run(
        [grains_bin, "run", str(path), "--steps", str(STEPS), "--out", str(tmp_path),
         "--set", "output.dump=true", "--quiet"],
        check=True,
    )
    sim = grains.Simulation(path)
    # Several calls, stretches of any length: the same bits.
    sim.run(steps=100)
    sim.run(steps=STEPS - 100)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert sim.kinetic_energy == summary["kinetic_energy"]
    ids, pos, vel = final_state(tmp_path)
    assert np.array_equal(sim.positions, pos[:, :2])
    assert np.array_equal(sim.velocities, vel[:, :2])


def test_dsmc_matches_grains_run(scenarios, tmp_path):
    path = scenarios / "gas-vibrated-2d.toml"
    summary = grains.run(path, out=tmp_path, steps=STEPS)
    sim = grains.Simulation(path)
    assert sim.method == "dsmc"
    sim.run(steps=STEPS)
    assert sim.kinetic_energy == summary["kinetic_energy"]
    assert sim.summary()["collisions"] == summary["collisions"]
    assert sim.summary()["validity"] == summary["validity"]
    csv = read_thermo(tmp_path / "thermo.csv")
    for col in csv:
        assert np.array_equal(np.asarray(sim.thermo[col], dtype=float), np.array(csv[col])), col


@pytest.mark.parametrize("name", ["pour-3d.toml", "gas-vibrated-3d.toml"])
def test_checkpoint_resumes_bit_for_bit(scenarios, tmp_path, name):
    straight = grains.Simulation(scenarios / name)
    straight.run(steps=200)
    first = grains.Simulation(scenarios / name)
    first.run(steps=120)
    ck = first.save_checkpoint(tmp_path / "sim.grck")
    resumed = grains.Simulation.resume(ck)
    assert resumed.step == 120
    resumed.run(steps=80)
    assert np.array_equal(resumed.positions, straight.positions)
    assert np.array_equal(resumed.velocities, straight.velocities)
    assert resumed.kinetic_energy == straight.kinetic_energy


def test_setter_then_run_matches_a_scenario_from_those_positions(scenarios, tmp_path):
    """Set the grains of the convection scenario to new positions and
    velocities, then run: the same bits as a scenario placing them from a
    CSV file."""
    path = scenarios / "seed-convection-modulated.toml"
    sim = grains.Simulation(path)
    rng = np.random.default_rng(7)
    pos = sim.positions + rng.uniform(-0.02, 0.02, sim.positions.shape) * sim.diameters[:, None]
    vel = rng.normal(0.0, 0.05, pos.shape)
    sim.positions = pos
    sim.velocities = vel
    assert np.array_equal(sim.positions, pos)
    assert np.array_equal(sim.velocities, vel)
    sim.run(steps=STEPS)

    csv = tmp_path / "start.csv"
    with open(csv, "w") as f:
        f.write("id,x,y,diameter,vx,vy\n")
        for i, (x, v, d) in enumerate(zip(pos, vel, sim.diameters)):
            row = [float(y) for y in (x[0], x[1], d, v[0], v[1])]
            f.write(f"{sim.ids[i]}," + ",".join(repr(y) for y in row) + "\n")
    scenario = grains.Scenario.load(path)
    scenario.set("particles.placement", "file").set("particles.file", str(csv))
    other = grains.Simulation(scenario)
    other.run(steps=STEPS)
    assert np.array_equal(other.positions, sim.positions)
    assert np.array_equal(other.velocities, sim.velocities)
    assert other.kinetic_energy == sim.kinetic_energy
