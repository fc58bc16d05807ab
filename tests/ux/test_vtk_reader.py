#!/usr/bin/env python3
"""test_vtk_reader.py FLEXMBD SCENE OUTDIR — the animation read by VTK's own XML reader (Debian's
python3-vtk9, the library ParaView is built on), not by our own parsing: every .vtu of the
collection loads without a reader error, as an unstructured grid whose points on the beam's
centreline are the CSV's BEAM.shape columns (1e-12), whose cells are the expected VTK types, with
the point data `deformation` (3 components), `rotation` and the cell data `part` and `owner`.
Exit 77 (skipped) when this Python has no vtk module."""
import csv
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

try:
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
except ImportError:
    print("SKIP: no vtk module in", sys.executable, "(Debian: apt-get install python3-vtk9)")
    sys.exit(77)

flexmbd, scene, out = sys.argv[1:4]
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
csv_path, anim = os.path.join(out, "run.csv"), os.path.join(out, "anim")
r = subprocess.run([flexmbd, "run", scene, "-o", csv_path, "--vtk", anim], capture_output=True, text=True)
if r.returncode != 0:
    sys.exit(f"FAIL: run exited {r.returncode}: {r.stderr}")
rows = list(csv.DictReader(open(csv_path)))
stem = os.path.splitext(os.path.basename(scene))[0]
files = [d.get("file") for d in ET.parse(os.path.join(anim, stem + ".pvd")).getroot().iter("DataSet")]
failures = []
errors = []
if len(files) != len(rows):
    failures.append(f"{len(files)} files for {len(rows)} rows")
for name, row in zip(files, rows):
    reader = vtkXMLUnstructuredGridReader()
    reader.AddObserver("ErrorEvent", lambda obj, ev: errors.append(name))
    reader.SetFileName(os.path.join(anim, name))
    reader.Update()
    grid = reader.GetOutput()
    if reader.GetErrorCode() != 0 or name in errors or grid.GetNumberOfPoints() == 0:
        failures.append(f"{name}: VTK could not read it")
        continue
    part = grid.GetCellData().GetArray("part")
    owner = grid.GetCellData().GetArray("owner")
    deform = grid.GetPointData().GetArray("deformation")
    if part is None or owner is None or deform is None or deform.GetNumberOfComponents() != 3 or grid.GetPointData().GetArray("rotation") is None:
        failures.append(f"{name}: missing data arrays")
        continue
    t = grid.GetFieldData().GetArray("TimeValue").GetValue(0)
    if abs(t - float(row["t"])) > 1e-12 * max(1.0, abs(t)):
        failures.append(f"{name}: TimeValue {t} != CSV t {row['t']}")
    types = sorted({grid.GetCellType(c) for c in range(grid.GetNumberOfCells())})
    if types != [1, 3, 4]:
        failures.append(f"{name}: cell types {types}, expected vertex, line and polyline")
    for c in range(grid.GetNumberOfCells()):
        if part.GetValue(c) != 0:
            continue
        ids = grid.GetCell(c).GetPointIds()
        for s in range(ids.GetNumberOfIds()):
            x, y, _ = grid.GetPoint(ids.GetId(s))
            cx, cy = float(row[f"arm.shape{s}_x"]), float(row[f"arm.shape{s}_y"])
            if abs(x - cx) > 1e-12 * max(1, abs(cx)) or abs(y - cy) > 1e-12 * max(1, abs(cy)):
                failures.append(f"{name}: station {s} at ({x}, {y}), CSV ({cx}, {cy})")
for f in failures[:20]:
    print("FAIL:", f)
if not failures:
    print(f"ok: VTK {__import__('vtk').vtkVersion.GetVTKVersion()} read {len(files)} files; centrelines equal the CSV")
sys.exit(1 if failures else 0)
