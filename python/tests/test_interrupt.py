"""run() releases the GIL and answers Ctrl-C."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import grains


def test_run_releases_the_gil(scenarios):
    sim = grains.Simulation(scenarios / "bench-vib2d.toml")
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    start = time.perf_counter()
    sim.run(steps=3000)
    end = time.perf_counter()
    done.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    # A thread holding the GIL for the whole run would leave no ticks.
    assert len(during) > 0.3 * (end - start) / 0.001 * 0.5


@pytest.mark.skipif(os.name != "posix", reason="SIGINT by os.kill")
def test_ctrl_c_stops_within_a_second_at_a_complete_step(scenarios):
    sim = grains.Simulation(scenarios / "bench-vib2d.toml")
    sent = []

    def interrupt():
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(0.5, interrupt)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        sim.run(steps=10_000_000)
    caught = time.perf_counter()
    timer.join()
    assert caught - sent[0] < 1.0
    step = sim.step
    assert 0 < step < 10_000_000
    # A complete step: time and state agree, and it runs on.
    assert sim.time == pytest.approx(step * sim.dt, rel=1e-12)
    assert np.isfinite(sim.positions).all()
    sim.run(steps=10)
    assert sim.step == step + 10


@pytest.mark.skipif(os.name != "posix", reason="SIGINT by os.kill")
def test_ctrl_c_stops_grains_run_with_a_checkpoint(scenarios, tmp_path):
    """As `grains run` on SIGINT: the run stops at its next check, writes a
    checkpoint, and Python gets KeyboardInterrupt; Simulation.resume
    continues from the checkpoint."""
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        grains.run(scenarios / "bench-vib2d.toml", out=tmp_path, steps=10_000_000)
    timer.join()
    assert time.perf_counter() - start < 1.5
    checkpoints = sorted(tmp_path.glob("checkpoint-*.grck"))
    assert len(checkpoints) == 1
    sim = grains.Simulation.resume(tmp_path)
    assert sim.step > 0 and str(sim.step) in checkpoints[0].name
