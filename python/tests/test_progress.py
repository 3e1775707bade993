"""Simulation.run(progress=True): a bar on sys.stderr, off by default."""

import grains


def test_run_draws_a_progress_bar_only_when_asked(scenarios, capsys):
    sim = grains.Simulation(scenarios / "seed-convection-modulated.toml")
    sim.run(steps=30)
    assert capsys.readouterr().err == ""
    sim.run(steps=50, progress=True)
    err = capsys.readouterr().err
    assert err.startswith("\r[") and err.endswith("\n"), repr(err)
    last = err.rstrip("\n").split("\r")[-1]
    assert "100% 50/50 steps" in last and "t = " in last, repr(err)
    assert sim.step == 80


def test_progress_is_documented():
    assert "progress" in grains.Simulation.run.__doc__
