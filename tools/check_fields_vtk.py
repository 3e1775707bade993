#!/usr/bin/env python3
"""Check a run's contact network and coarse-grained fields with VTK's readers.

Usage: python3 tools/check_fields_vtk.py RUN_DIR

Reads RUN_DIR/contacts/*.vtp (`output.contacts = true`) with
vtkXMLPolyDataReader and RUN_DIR/fields/*.vti (`[measure.fields]`) with
vtkXMLImageDataReader, and checks that
* every contacts file parses without a VTK error, has 2 points per line
  cell, the cell arrays force, normal_force, overlap, id1, id2, wall (1
  component) and tangential_force (3), and that its row count equals the
  matching .csv's; force >= 0;
* every fields file parses, has the point arrays density, packing_fraction,
  temperature, coordination (1), velocity (3), kinetic_stress,
  contact_stress, stress, fabric (9), density >= 0, and
  stress = kinetic_stress + contact_stress;
* contacts.pvd and fields.pvd list existing files.
Prints a line per file; exits 1 on a failure, 2 on usage errors.
"""

import glob
import os
import sys
import xml.etree.ElementTree as ET

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkOutputWindow
from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLPolyDataReader


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    run = sys.argv[1]
    vtkOutputWindow.GetInstance().SetDisplayMode(0)
    bad = []
    for path in sorted(glob.glob(os.path.join(run, "contacts", "*.vtp"))):
        r = vtkXMLPolyDataReader()
        r.SetFileName(path)
        r.Update()
        if r.GetErrorCode():
            bad.append(f"{path}: VTK error {r.GetErrorCode()}")
            continue
        out = r.GetOutput()
        n = out.GetNumberOfCells()
        if out.GetNumberOfPoints() != 2 * n:
            bad.append(f"{path}: {out.GetNumberOfPoints()} points for {n} lines")
        cd = out.GetCellData()
        for name, comps in [("force", 1), ("normal_force", 1), ("overlap", 1), ("id1", 1),
                            ("id2", 1), ("wall", 1), ("tangential_force", 3)]:
            a = cd.GetArray(name)
            if a is None or a.GetNumberOfComponents() != comps or a.GetNumberOfTuples() != n:
                bad.append(f"{path}: cell array {name} missing or misshapen")
        if n and cd.GetArray("force") is not None and vtk_to_numpy(cd.GetArray("force")).min() < 0:
            bad.append(f"{path}: negative force magnitude")
        csv = path[:-4] + ".csv"
        rows = sum(1 for _ in open(csv)) - 1 if os.path.exists(csv) else -1
        if rows != n:
            bad.append(f"{path}: {n} lines but {rows} rows in the CSV")
        print(f"{path}: {n} contacts")
    for path in sorted(glob.glob(os.path.join(run, "fields", "*.vti"))):
        r = vtkXMLImageDataReader()
        r.SetFileName(path)
        r.Update()
        out = r.GetOutput()
        n = out.GetNumberOfPoints()
        pd = out.GetPointData()
        arrays = {}
        for name, comps in [("density", 1), ("packing_fraction", 1), ("temperature", 1),
                            ("coordination", 1), ("velocity", 3), ("kinetic_stress", 9),
                            ("contact_stress", 9), ("stress", 9), ("fabric", 9)]:
            a = pd.GetArray(name)
            if a is None or a.GetNumberOfComponents() != comps or a.GetNumberOfTuples() != n:
                bad.append(f"{path}: point array {name} missing or misshapen")
            else:
                arrays[name] = vtk_to_numpy(a)
        if len(arrays) == 9:
            if arrays["density"].min() < 0:
                bad.append(f"{path}: negative density")
            gap = abs(arrays["stress"] - arrays["kinetic_stress"] - arrays["contact_stress"]).max()
            scale = max(abs(arrays["stress"]).max(), 1e-300)
            if gap > 1e-12 * scale:
                bad.append(f"{path}: stress != kinetic + contact ({gap})")
        print(f"{path}: {n} points, dims {out.GetDimensions()}")
    for pvd in ["contacts.pvd", "fields.pvd"]:
        p = os.path.join(run, pvd)
        if not os.path.exists(p):
            continue
        for ds in ET.parse(p).getroot().iter("DataSet"):
            if not os.path.exists(os.path.join(run, ds.get("file"))):
                bad.append(f"{p}: lists missing {ds.get('file')}")
    for b in bad:
        print("FAIL", b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
