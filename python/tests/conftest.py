"""Shared fixtures of the grains Python tests."""

import os
import pathlib
import shutil

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "scenarios"


@pytest.fixture
def scenarios():
    """The shipped scenarios' directory."""
    return SCENARIOS


@pytest.fixture
def grains_bin():
    """The built `grains` command line: $GRAINS_BIN, else skip.

    CI builds it (`cargo build --release -p grains-cli`) and sets the
    variable in .ci/python.sh.
    """
    path = os.environ.get("GRAINS_BIN")
    if not path:
        pytest.skip("GRAINS_BIN is not set: build the CLI (cargo build --release -p grains-cli) and point GRAINS_BIN at it")
    if not (os.path.isfile(path) and os.access(path, os.X_OK)) and not shutil.which(path):
        pytest.fail(f"GRAINS_BIN={path} is not an executable file")
    return path


def read_dump_last(path):
    """The last frame of a LAMMPS dump written by grains: {id: (x, y, z, vx, vy, vz)}."""
    lines = pathlib.Path(path).read_text().splitlines()
    start = max(i for i, l in enumerate(lines) if l.startswith("ITEM: ATOMS"))
    n = int(lines[start - 5])  # the count, above the three box lines and their header
    rows = {}
    for line in lines[start + 1 : start + 1 + n]:
        f = line.split()
        rows[int(f[0])] = tuple(float(x) for x in f[3:9])
    return rows


def read_thermo(path):
    """thermo.csv as {column: [values]}."""
    lines = pathlib.Path(path).read_text().splitlines()
    cols = lines[0].split(",")
    rows = [[float(x) for x in l.split(",")] for l in lines[1:] if l]
    return {c: [r[k] for r in rows] for k, c in enumerate(cols)}
