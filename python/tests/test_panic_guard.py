"""A Rust panic inside a binding call (a bug of grains) reaches Python as a
`RuntimeError` that says so, never as a process abort nor as PyO3's
`PanicException` (a `BaseException`, which `except Exception` misses).

The panic comes from `grains._native._panic_for_tests`, a hidden entry
point that panics inside the same guard every binding call goes through;
with `on_pool=True` it panics as `Simulation.run` would, on a worker of a
thread pool with the GIL released."""

import subprocess
import sys

import pytest

import grains
from grains import _native


@pytest.mark.parametrize("on_pool", [False, True], ids=["caller", "pool"])
def test_a_panic_is_a_runtime_error(on_pool):
    with pytest.raises(RuntimeError) as caught:
        _native._panic_for_tests("planted panic 7", on_pool=on_pool)
    # A RuntimeError of its own, not PyO3's PanicException (whose base is
    # BaseException) nor one of the library's errors.
    assert type(caught.value) is RuntimeError
    assert not isinstance(caught.value, grains.UnstableError)
    text = str(caught.value)
    assert "planted panic 7" in text and "bug" in text, text


def test_the_process_lives_on_after_a_panic(scenarios):
    """In a process of its own, so that an abort fails this test and not
    the whole run: the panic is caught by an ordinary `except Exception`,
    and the module still works afterwards."""
    code = (
        "import grains, grains._native as n\n"
        "for pool in (False, True):\n"
        "    try:\n"
        "        n._panic_for_tests('planted', on_pool=pool)\n"
        "    except Exception as e:\n"
        "        print(type(e).__name__)\n"
        f"sim = grains.Simulation({str(scenarios / 'pour-3d.toml')!r}, threads=2)\n"
        "sim.run(steps=10)\n"
        "print(sim.step)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["RuntimeError", "RuntimeError", "10"], out.stdout + out.stderr
