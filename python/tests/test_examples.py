"""The examples in examples/python: without matplotlib (which `pip install .`
does not bring) each says what to install and exits, with no traceback."""

import pathlib
import subprocess
import sys

import pytest

EXAMPLES = sorted((pathlib.Path(__file__).resolve().parents[2] / "examples" / "python").glob("*.py"))

# Runs an example as a script with `import matplotlib` failing as it does
# where it is not installed.
BLOCKED = """
import runpy, sys
sys.modules["matplotlib"] = None
sys.argv = [sys.argv[1]]
runpy.run_path(sys.argv[0], run_name="__main__")
"""


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.name)
def test_example_without_matplotlib_says_what_to_install(example, tmp_path):
    run = subprocess.run(
        [sys.executable, "-c", BLOCKED, str(example)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 1, run.stderr
    assert "pip install '.[examples]'" in run.stderr, run.stderr
    assert "Traceback" not in run.stderr, run.stderr
    # Nothing written into the current folder.
    assert list(tmp_path.iterdir()) == []


def test_examples_are_found():
    assert len(EXAMPLES) >= 2
