#!/usr/bin/python3
"""Reads the VTK files written by sphere back with VTK's own XML reader and checks them.

usage: /usr/bin/python3 tests/vtk_read.py [--writer EXE] DIR

With --writer, DIR is emptied and `EXE DIR` (tests/vtk_writer_main.cpp) writes into it first.
For each of DIR/float and DIR/double: the .pvd collection is parsed with xml.etree and must list
the frames of expected.json (file names and times); every .vtu is read with
vtkXMLUnstructuredGridReader and must hold one VTK_VERTEX cell per particle, the point count,
the positions, the TimeValue field and every point-data array of expected.json (the values the
writer took directly from the simulation), with the right type and number of components.
Independently of the writer, the mass of every particle must be 4/3 pi r^3 rho, the fixed
particle must stay where it is with zero velocity, and the prescribed one must keep its velocity.

Exit status: 0 when everything matches, 1 on any mismatch (each is printed), 77 when this Python
cannot import VTK (Debian's python3-vtk9 serves /usr/bin/python3 only), 2 on bad usage.
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

try:
    from vtkmodules.vtkCommonCore import VTK_DOUBLE, VTK_FLOAT, VTK_UNSIGNED_CHAR
    from vtkmodules.vtkCommonDataModel import VTK_VERTEX
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
except ImportError as error:
    print(f"SKIP: {sys.executable} cannot import VTK ({error}); install python3-vtk9")
    sys.exit(77)

# The writer prints max_digits10 significant digits (17 for double, 9 for float), enough for
# VTK's reader to parse back the very value the simulation held: values read must equal the
# writer's (expected.json holds them converted to double, with 17 digits) exactly.
TOLERANCE = {"double": 0.0, "float": 0.0}
# Analytic checks compare with values computed here in double: a float value differs from them
# by its rounding, at most half a float ulp (6e-8 relative); allow 2e-7. Double: 1e-15.
ANALYTIC = {"double": 1e-15, "float": 2e-7}
VTK_TYPE = {"double": VTK_DOUBLE, "float": VTK_FLOAT}
VECTORS = ["velocity", "angular_velocity", "angular_position", "force", "torque", "accumulated_displacement"]
SCALARS = ["radius", "mass", "pressure", "dissipated_viscous", "dissipated_frictional"]

failures = []


def fail(message):
    failures.append(message)
    print("MISMATCH: " + message)


def close(a, b, tol):
    return a == b or abs(a - b) <= tol * max(abs(a), abs(b))


def check_frame(folder, precision, frame, tol, setup):
    path = os.path.join(folder, frame["file"])
    where = f"{precision}/{frame['file']}"
    if not os.path.isfile(path):
        fail(f"{where}: file missing")
        return None
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode() != 0:
        fail(f"{where}: VTK reader error code {reader.GetErrorCode()}")
    grid = reader.GetOutput()
    n = frame["points"]
    if grid.GetNumberOfPoints() != n:
        fail(f"{where}: {grid.GetNumberOfPoints()} points, expected {n}")
        return None
    if grid.GetNumberOfCells() != n:
        fail(f"{where}: {grid.GetNumberOfCells()} cells, expected {n}")
    for c in range(grid.GetNumberOfCells()):
        if grid.GetCellType(c) != VTK_VERTEX or grid.GetCell(c).GetPointId(0) != c:
            fail(f"{where}: cell {c} is not the vertex of point {c}")
            break

    times = grid.GetFieldData().GetArray("TimeValue")
    if times is None or not close(times.GetValue(0), frame["time"], 0.0):
        fail(f"{where}: TimeValue {times and times.GetValue(0)}, expected {frame['time']}")

    points = grid.GetPoints()
    if points.GetDataType() != VTK_TYPE[precision]:
        fail(f"{where}: points have VTK type {points.GetDataType()}, expected {VTK_TYPE[precision]}")
    for i in range(n):
        got, want = points.GetPoint(i), frame["position"][i]
        if not all(close(got[k], want[k], tol) for k in range(3)):
            fail(f"{where}: point {i} at {got}, expected {want}")

    data = grid.GetPointData()
    read = {}
    for name in VECTORS + SCALARS + ["kind", "material"]:
        array = data.GetArray(name)
        if array is None:
            fail(f"{where}: no point-data array '{name}'")
            continue
        components = 3 if name in VECTORS else 1
        vtk_type = VTK_UNSIGNED_CHAR if name in ("kind", "material") else VTK_TYPE[precision]
        if array.GetNumberOfComponents() != components or array.GetNumberOfTuples() != n:
            fail(f"{where}: '{name}' has {array.GetNumberOfTuples()} tuples of {array.GetNumberOfComponents()}, "
                 f"expected {n} of {components}")
            continue
        if array.GetDataType() != vtk_type:
            fail(f"{where}: '{name}' has VTK type {array.GetDataType()}, expected {vtk_type}")
        values = [array.GetTuple(i) if components == 3 else array.GetTuple(i)[0] for i in range(n)]
        read[name] = values
        for i in range(n):
            got, want = values[i], frame[name][i]
            ok = all(close(got[k], want[k], tol) for k in range(3)) if components == 3 else close(got, want, tol)
            if not ok:
                fail(f"{where}: '{name}' of particle {i} is {got}, expected {want}")
                break

    # Checks that do not depend on the writer's own numbers.
    rho = setup["density"]
    # The writer computed 4/3 pi r^3 rho in its precision: a few roundings, 1e-6 (float) or
    # 1e-13 (double) relative covers them.
    mass_tol = 1e-13 if precision == "double" else 1e-6
    for i, (r, m) in enumerate(zip(read.get("radius", []), read.get("mass", []))):
        if not close(m, 4.0 / 3.0 * math.pi * r ** 3 * rho, mass_tol):
            fail(f"{where}: particle {i} has mass {m} kg, 4/3 pi r^3 rho = {4.0 / 3.0 * math.pi * r ** 3 * rho}")
    kinds = read.get("kind", [])
    fixed, prescribed = setup["fixed_particle"], setup["prescribed_particle"]
    if kinds and (kinds[fixed] != 2 or kinds[prescribed] != 1 or any(k != 0 for j, k in enumerate(kinds)
                                                                     if j not in (fixed, prescribed))):
        fail(f"{where}: kinds {kinds}, expected 2 for particle {fixed}, 1 for {prescribed}, 0 otherwise")
    if "velocity" in read:
        if read["velocity"][fixed] != (0.0, 0.0, 0.0):
            fail(f"{where}: the fixed particle moves at {read['velocity'][fixed]}")
        if not all(close(a, b, ANALYTIC[precision])
                   for a, b in zip(read["velocity"][prescribed], setup["prescribed_velocity"])):
            fail(f"{where}: the prescribed particle moves at {read['velocity'][prescribed]}, "
                 f"expected {setup['prescribed_velocity']}")
    return points.GetPoint(fixed)


def check_precision(folder, precision):
    with open(os.path.join(folder, "expected.json")) as f:
        setup = json.load(f)
    frames = setup["frames"]
    tol = TOLERANCE[precision]

    pvd = ET.parse(os.path.join(folder, setup["pvd"])).getroot()
    if pvd.get("type") != "Collection":
        fail(f"{precision}: the .pvd is a '{pvd.get('type')}', not a Collection")
    datasets = pvd.findall("./Collection/DataSet")
    if len(datasets) != len(frames):
        fail(f"{precision}: the .pvd lists {len(datasets)} data sets, expected {len(frames)}")
    for d, frame in zip(datasets, frames):
        if d.get("file") != frame["file"] or not close(float(d.get("timestep")), frame["time"], 0.0):
            fail(f"{precision}: .pvd entry ({d.get('timestep')}, {d.get('file')}), "
                 f"expected ({frame['time']}, {frame['file']})")

    fixed_positions = []
    for frame in frames:
        fixed_positions.append(check_frame(folder, precision, frame, tol, setup))
    if len(set(p for p in fixed_positions if p is not None)) > 1:
        fail(f"{precision}: the fixed particle moved: {fixed_positions}")
    # The run is eventful: something touches, so some pressure is positive in the last frame.
    if not any(p > 0 for p in frames[-1]["pressure"]):
        fail(f"{precision}: no contact in the last frame; the test would not see force fields")
    print(f"{precision}: {len(frames)} frames of {frames[0]['points']} points checked")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--writer", help="run this program with DIR first (vtk_writer_for_test)")
    parser.add_argument("dir")
    args = parser.parse_args()
    if args.writer:
        shutil.rmtree(args.dir, ignore_errors=True)
        os.makedirs(args.dir)
        result = subprocess.run([args.writer, args.dir])
        if result.returncode != 0:
            print(f"FAILED: {args.writer} {args.dir} exited with {result.returncode}")
            return 1
    for precision in ("float", "double"):
        check_precision(os.path.join(args.dir, precision), precision)
    if failures:
        print(f"FAILED: {len(failures)} mismatches")
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
