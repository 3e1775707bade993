"""Output folders that never mix runs, and restarts under changed keys."""

import pytest

import grains


def test_a_folder_that_holds_a_run_is_refused_unless_overwritten(scenarios, tmp_path):
    path = scenarios / "seed-convection-modulated.toml"
    grains.run(path, out=tmp_path, steps=20)
    with pytest.raises(grains.InputError, match="overwrite"):
        grains.run(path, out=tmp_path, steps=10)
    ran = grains.run(path, out=tmp_path, steps=10, overwrite=True)
    assert ran["steps"] == 10


def test_from_checkpoint_continues_under_a_changed_law(scenarios, tmp_path):
    path = scenarios / "seed-convection-modulated.toml"
    grains.run(path, out=tmp_path, steps=40, checkpoint_every="40steps")
    same = grains.Simulation.from_checkpoint(tmp_path)
    changed = grains.Simulation.from_checkpoint(tmp_path, set={"contact.mu": 0.05})
    assert same.step == changed.step == 40
    same.run(steps=200)
    changed.run(steps=200)
    # The friction acted: the two continuations part.
    assert same.kinetic_energy != changed.kinetic_energy
    # The state is made of the grains: their number cannot change.
    with pytest.raises(grains.InputError, match="particles.count"):
        grains.Simulation.from_checkpoint(tmp_path, set={"particles.count": 10})
