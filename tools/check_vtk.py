#!/usr/bin/env python3
"""Check the VTK output of a `grains run` directory with a real VTK reader.

Usage: python3 tools/check_vtk.py RUN_DIR

Reads every RUN_DIR/frames/*.vtp with VTK's own XML PolyData reader (the
`vtk` package from PyPI: `python3 -m pip install vtk`; meshio cannot read
.vtp files) and RUN_DIR/frames.pvd, and checks that
(frames in pieces, `output.frames_layout = "pieces"`: every
RUN_DIR/frames/*.pvtp with VTK's parallel reader, which joins the pieces,
and then the same checks on the whole frame, ids unique across pieces)

* each frame parses without a VTK error or warning and has N points and N
  vertex cells (N > 0);
* the point arrays radius (1 component), velocity (3), angular_velocity (3),
  id (1) and type (1) exist with N tuples; radii are positive and ids unique;
* the field data carries TimeValue and Step;
* frames.pvd is a VTK Collection whose every DataSet file exists, is one of
  the frames, and whose timestep matches that frame's TimeValue; every frame
  is listed, and timesteps and steps increase;
* if RUN_DIR/summary.json exists: the last frame's Step equals its "steps"
  and its point count equals its "particles".

Exits 0 when all holds, 1 with a message per failure otherwise, 2 on usage
errors.
"""

import json
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

ARRAYS = {
    "radius": 1,
    "velocity": 3,
    "angular_velocity": 3,
    "id": 1,
    "type": 1,
}


def load_vtk():
    try:
        # Only the modules needed: no rendering libraries (GL, X11) load.
        from vtkmodules.vtkCommonCore import vtkCommand
        from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLPPolyDataReader
    except ImportError as e:
        sys.exit(f"check_vtk: the `vtk` Python package is needed "
                 f"(python3 -m pip install vtk): {e}")
    return vtkCommand, vtkXMLPolyDataReader, vtkXMLPPolyDataReader


class ErrorCatcher:
    """Collects VTK ErrorEvent/WarningEvent messages raised by a reader,
    which VTK otherwise only prints."""

    def __init__(self, obj, vtk_command):
        from vtkmodules.util.misc import calldata_type
        from vtkmodules.util.vtkConstants import VTK_STRING

        self.messages = []

        @calldata_type(VTK_STRING)
        def on_event(_obj, event, data=None):
            self.messages.append(f"{event}: {str(data).strip()}" if data else event)

        obj.AddObserver(vtk_command.ErrorEvent, on_event)
        obj.AddObserver(vtk_command.WarningEvent, on_event)
        self._keep = on_event


def read_frame(path, vtk_command, reader_cls, problems):
    """Reads and checks one .vtp; returns (points, time, step) or None."""
    reader = reader_cls()
    catcher = ErrorCatcher(reader, vtk_command)
    reader.SetFileName(str(path))
    reader.Update()
    if catcher.messages or reader.GetErrorCode() != 0:
        problems.append(f"{path}: VTK could not read it: "
                        + ("; ".join(catcher.messages)
                           or f"error code {reader.GetErrorCode()}"))
        return None
    pd = reader.GetOutput()
    n = pd.GetNumberOfPoints()
    if n <= 0:
        problems.append(f"{path}: no points")
        return None
    if pd.GetNumberOfVerts() != n:
        problems.append(f"{path}: {pd.GetNumberOfVerts()} vertex cells for {n} points")
    point_data = pd.GetPointData()
    for name, comps in ARRAYS.items():
        arr = point_data.GetArray(name)
        if arr is None:
            problems.append(f"{path}: point array '{name}' is missing")
            continue
        if arr.GetNumberOfComponents() != comps:
            problems.append(f"{path}: '{name}' has {arr.GetNumberOfComponents()} "
                            f"components, expected {comps}")
        if arr.GetNumberOfTuples() != n:
            problems.append(f"{path}: '{name}' has {arr.GetNumberOfTuples()} "
                            f"tuples for {n} points")
        values = [arr.GetComponent(i, c) for i in range(arr.GetNumberOfTuples())
                  for c in range(arr.GetNumberOfComponents())]
        if not all(math.isfinite(v) for v in values):
            problems.append(f"{path}: '{name}' has non-finite values")
        if name == "radius" and any(v <= 0 for v in values):
            problems.append(f"{path}: a radius is not positive")
        if name == "id" and len(set(values)) != len(values):
            problems.append(f"{path}: ids are not unique")
    pts = pd.GetPoints()
    if pts is not None:
        coords = [pts.GetPoint(i) for i in range(n)]
        if not all(math.isfinite(x) for p in coords for x in p):
            problems.append(f"{path}: non-finite point coordinates")
    field = pd.GetFieldData()
    time = field.GetArray("TimeValue")
    step = field.GetArray("Step")
    if time is None or step is None:
        problems.append(f"{path}: field data TimeValue/Step missing")
        return n, None, None
    return n, time.GetComponent(0, 0), int(step.GetComponent(0, 0))


def check_pvd(run_dir, frames, problems):
    pvd = run_dir / "frames.pvd"
    if not pvd.is_file():
        problems.append(f"{pvd}: missing")
        return
    try:
        root = ET.parse(pvd).getroot()
    except ET.ParseError as e:
        problems.append(f"{pvd}: not well-formed XML: {e}")
        return
    if root.tag != "VTKFile" or root.get("type") != "Collection":
        problems.append(f"{pvd}: not a VTK Collection file")
        return
    datasets = root.findall("./Collection/DataSet")
    if not datasets:
        problems.append(f"{pvd}: lists no DataSet")
        return
    listed = set()
    previous = None
    for k, ds in enumerate(datasets):
        rel = ds.get("file")
        ts = ds.get("timestep")
        if rel is None or ts is None:
            problems.append(f"{pvd}: DataSet {k} lacks file or timestep")
            continue
        target = (pvd.parent / rel).resolve()
        if not target.is_file():
            problems.append(f"{pvd}: DataSet {k} references {rel}, which does not exist")
            continue
        listed.add(target)
        try:
            t = float(ts)
        except ValueError:
            problems.append(f"{pvd}: DataSet {k} timestep '{ts}' is not a number")
            continue
        if previous is not None and t <= previous:
            problems.append(f"{pvd}: timestep {t} of DataSet {k} does not increase")
        previous = t
        info = frames.get(target)
        if info is not None and info[1] is not None:
            if not math.isclose(info[1], t, rel_tol=1e-12, abs_tol=1e-300):
                problems.append(f"{pvd}: DataSet {k} timestep {t} but {rel} has "
                                f"TimeValue {info[1]}")
    for f in frames:
        if f not in listed:
            problems.append(f"{pvd}: does not list {f}")


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    run_dir = Path(argv[1])
    if not run_dir.is_dir():
        print(f"check_vtk: {run_dir}: not a directory", file=sys.stderr)
        return 2
    vtk_command, serial_reader, parallel_reader = load_vtk()
    problems = []
    files = sorted((run_dir / "frames").glob("*.pvtp"))
    reader_cls = parallel_reader
    if not files:
        files = sorted((run_dir / "frames").glob("*.vtp"))
        reader_cls = serial_reader
    if not files:
        problems.append(f"{run_dir / 'frames'}: no .vtp files")
    frames = {}
    for f in files:
        info = read_frame(f, vtk_command, reader_cls, problems)
        if info is not None:
            frames[f.resolve()] = info
    counts = {info[0] for info in frames.values()}
    if len(counts) > 1:
        problems.append(f"{run_dir}: frames have different point counts {sorted(counts)}")
    steps = [info[2] for info in frames.values()]
    if None not in steps and steps != sorted(set(steps)):
        problems.append(f"{run_dir}: frame steps do not increase: {steps}")
    check_pvd(run_dir, frames, problems)
    summary = run_dir / "summary.json"
    if summary.is_file() and frames:
        s = json.loads(summary.read_text())
        last = frames[max(frames)]
        if "steps" in s and last[2] != s["steps"]:
            problems.append(f"{run_dir}: last frame is step {last[2]}, summary.json "
                            f"says {s['steps']} steps")
        if "particles" in s and last[0] != s["particles"]:
            problems.append(f"{run_dir}: last frame has {last[0]} points, "
                            f"summary.json says {s['particles']} particles")
    if problems:
        for p in problems:
            print(f"check_vtk: {p}", file=sys.stderr)
        print(f"check_vtk: FAILED ({len(problems)} problems)", file=sys.stderr)
        return 1
    n = next(iter(counts))
    print(f"check_vtk: OK: {len(frames)} frames of {n} points and frames.pvd in {run_dir}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
