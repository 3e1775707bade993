"""Coarse-grained fields as numpy arrays (Simulation.fields, docs/fields.md)."""

import csv

import numpy as np
import pytest

import grains

G = 9.81


def bed(scenarios, **sets):
    """The 2D bed of docs/fields.md with `sets` applied."""
    s = grains.Scenario.load(scenarios / "bed-fields-2d.toml")
    for k, v in {"output.picture": False, **sets}.items():
        s.set(k, v)
    return s


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def test_fields_are_those_grains_run_writes(scenarios, tmp_path):
    """The settled bed, profiles along the periodic x axis sampled every
    200 steps for 0.01 s in windows of 2: each window's arrays are the
    columns of fields/fields_0000k.csv that `grains run` writes, bit for
    bit (the CSV carries round-trip decimals), and Σ density ×
    point_volume is the grains' mass to rounding (the weights are
    normalised on the lattice; along a periodic axis none fall outside)."""
    sets = {
        "measure.fields.axes": ["x"],
        "measure.fields.cells": [40],
        "run.duration": 0.01,
        "measure.fields.average": 2,
        "output.frames": False,
        "output.contacts": False,
    }
    grains.run(bed(scenarios, **sets), out=tmp_path / "run", threads=1)
    sim = grains.Simulation(bed(scenarios, **sets), threads=1)
    assert sim.fields() is None  # no sample before the measurement
    sim.run()
    files = sorted((tmp_path / "run" / "fields").glob("fields_*.csv"))
    assert len(files) == 3
    mass = sim.masses.sum()
    for k, path in enumerate(files):
        c = read_csv(path)
        f = sim.fields(k)
        n = len(c["x"])
        assert f["axes"] == ["x"]
        assert f["density"].shape == (n,)
        assert f["velocity"].shape == (n, 2)
        assert f["stress"].shape == (n, 2, 2)
        assert np.array_equal(f["x"], c["x"])
        for name in ["density", "packing_fraction", "temperature", "coordination"]:
            assert np.array_equal(f[name], c[name]), name
        for a, ax in enumerate("xy"):
            assert np.array_equal(f["velocity"][:, a], c["v" + ax])
            for b, bx in enumerate("xy"):
                for t in ["stress", "kinetic_stress", "contact_stress", "fabric"]:
                    assert np.array_equal(f[t][:, a, b], c[f"{t}_{ax}{bx}"]), (t, ax, bx)
        # The lattice-normalised weights hold the mass exactly (to rounding).
        assert f["density"].sum() * f["point_volume"] == pytest.approx(mass, rel=1e-12)
    assert sim.fields(-1)["times"] == sim.fields(len(files) - 1)["times"]
    with pytest.raises(IndexError, match="window"):
        sim.fields(len(files))


def test_settled_bed_carries_the_weight_above(scenarios):
    """The bed at rest (0.6 s settling, 0.2 s of samples in one window,
    Gaussian w = d0, 60 points along y): σ_yy(y) equals the weight of the
    grains above, g ∫_y^top ρ dy' of the coarse-grained density
    (Weinhart et al. 2012: the contact stress spread along the branch
    vectors makes the momentum balance exact): from 3w above the floor
    (where the floor's reaction is out of the kernel's reach) up to where
    σ_yy falls to 10 % of its floor value within 1 % (measured 3.5e-3),
    and everywhere above 3w within 2e-3 of the floor value (measured
    8e-4 near the surface). The error there is the trapezoid rule's on 60
    points (h = w/2) where ρ bends at the surface, not the stress's.
    σ_xy is under 1 % of σ_yy at the floor."""
    sim = grains.Simulation(bed(scenarios, **{"output.frames": False}), threads=1)
    sim.run()
    f = sim.fields()
    assert f["samples"] == 126
    y, rho = f["y"], f["density"]
    # Weight above each point: trapezoids from the top (ρ vanishes there).
    h = y[1] - y[0]
    assert rho[-1] == 0.0
    above = np.concatenate([np.cumsum(0.5 * (rho[1:] + rho[:-1])[::-1] * h)[::-1], [0.0]])
    weight = G * above
    syy = f["stress"][:, 1, 1]
    floor = syy.max()
    w = 1.0e-3  # the kernel's width, d0
    bulk = (y >= 3 * w) & (syy >= 0.1 * floor)
    assert bulk.sum() >= 15
    err = np.abs(syy[bulk] - weight[bulk]) / weight[bulk]
    assert err.max() < 0.01, err.max()
    above_floor = y >= 3 * w
    err = np.abs(syy[above_floor] - weight[above_floor]) / floor
    assert err.max() < 2e-3, err.max()
    assert np.abs(f["stress"][:, 0, 1]).max() < 0.01 * floor


def test_a_two_axis_grid_is_indexed_x_then_y(scenarios):
    """A grid along x and y comes back with shape (cells_x, cells_y),
    density[i, j] at (x[i], y[j]): on the settled bed every x column is
    empty above the grains (beyond the Gaussian's 3w reach) and filled in
    the bed's middle. Laid out the wrong way, the empty points (the last
    ones in the library's order, x fastest) would fill the last x rows."""
    sets = {
        "measure.fields.axes": ["x", "y"],
        "measure.fields.cells": [4, 30],
        "output.frames": False,
        "output.contacts": False,
    }
    sim = grains.Simulation(bed(scenarios, **sets), threads=1)
    sim.run()
    f = sim.fields()
    rho = f["density"]
    assert f["axes"] == ["x", "y"]
    assert rho.shape == (4, 30) and f["x"].shape == (4,) and f["y"].shape == (30,)
    assert f["velocity"].shape == (4, 30, 2) and f["stress"].shape == (4, 30, 2, 2)
    assert np.all(np.diff(f["x"]) > 0) and np.all(np.diff(f["y"]) > 0)
    w = 1.0e-3  # the kernel's width, d0
    top = (sim.positions[:, 1] + sim.diameters / 2).max()
    empty = f["y"] > top + 3 * w
    middle = np.abs(f["y"] - top / 2) < w
    assert empty.sum() >= 5 and middle.sum() >= 1
    assert np.all(rho[:, empty] == 0.0)
    assert np.all(rho[:, middle] > 0.3 * rho.max())


def test_fields_refused_without_the_table(scenarios):
    """A scenario without [measure.fields] names the table."""
    sim = grains.Simulation(scenarios / "two-particle-collision.toml")
    with pytest.raises(grains.InputError, match=r"\[measure.fields\]"):
        sim.fields()
