"""Output folders that never mix runs, and restarts under changed keys."""

import numpy as np
import pytest

import grains


def test_a_folder_that_holds_a_run_is_refused_unless_overwritten(scenarios, tmp_path):
    path = scenarios / "seed-convection-modulated.toml"
    grains.run(path, out=tmp_path, steps=20)
    with pytest.raises(grains.InputError, match="overwrite"):
        grains.run(path, out=tmp_path, steps=10)
    ran = grains.run(path, out=tmp_path, steps=10, overwrite=True)
    assert ran["steps"] == 10


def test_from_checkpoint_continues_under_changed_gravity(scenarios, tmp_path):
    path = scenarios / "seed-convection-modulated.toml"
    grains.run(path, out=tmp_path, steps=40, checkpoint_every="40steps")
    same = grains.Simulation.from_checkpoint(tmp_path)
    changed = grains.Simulation.from_checkpoint(tmp_path, set={"gravity": [0.0, -3.0]})
    assert same.step == changed.step == 40
    # Gear-5 carries the old acceleration in its history: the switch has a
    # transient of a few steps, as in a run whose gravity switched there.
    same.run(steps=100)
    changed.run(steps=100)
    v_same, v_changed = same.velocities, changed.velocities
    same.run(steps=200)
    changed.run(steps=200)
    # Most grains are still falling free: each gained g t in vertical
    # velocity, with the gravity of its own continuation.
    t = 200 * same.dt
    dv_same = (same.velocities - v_same)[:, 1]
    dv_changed = (changed.velocities - v_changed)[:, 1]
    free = np.abs(dv_same + 9.81 * t) < 1e-9 * 9.81 * t
    assert free.mean() > 0.8
    np.testing.assert_allclose(dv_changed[free], -3.0 * t, rtol=1e-9)
    # The state is made of the grains: their number cannot change.
    with pytest.raises(grains.InputError, match="particles.count"):
        grains.Simulation.from_checkpoint(tmp_path, set={"particles.count": 10})
