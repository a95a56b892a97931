#!/usr/bin/python3
"""Reads the fluid .vti files written by sphere (include/sphere/io/vti.cuh) back with VTK's own
vtkXMLImageDataReader and checks them.

usage:
  /usr/bin/python3 tests/read_vti.py --writer EXE DIR
      DIR is emptied, `EXE DIR` (tests/vti_writer_main.cpp) writes known fields into DIR/float
      and DIR/double, and every cell value of both frames is compared with the formulas of that
      program, exactly (the writer prints enough digits to read back the very value).
  /usr/bin/python3 tests/read_vti.py --pvd DIR/fluid.pvd --dims NX NY NZ
        [--check NAME[:COMPONENT] CELL VALUE RELTOL]... [--range NAME LO HI]...
      every frame the .pvd lists must be readable, with NX x NY x NZ cells, the cell arrays
      pressure, velocity (3 components) and porosity, and the .pvd's time as TimeValue; the
      checks apply to the last frame: cell CELL (VTK's cell id, x fastest) of array NAME
      within RELTOL of VALUE (relative; 0 means exactly), every cell of NAME in [LO, HI].

Exit status: 0 when everything matches, 1 on any mismatch (each is printed), 77 when this Python
cannot import VTK (Debian's python3-vtk9 serves /usr/bin/python3 only), 2 on bad usage.
"""

import argparse
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

try:
    from vtkmodules.vtkCommonCore import VTK_DOUBLE, VTK_FLOAT
    from vtkmodules.vtkIOXML import vtkXMLImageDataReader
except ImportError as error:
    print(f"SKIP: {sys.executable} cannot import VTK ({error}); install python3-vtk9")
    sys.exit(77)

failures = []


def fail(message):
    failures.append(message)
    print("MISMATCH: " + message)


def close(a, b, tol):
    return a == b or abs(a - b) <= tol * max(abs(a), abs(b))


def read(path):
    """The vtkImageData of a .vti file, or None (a mismatch is recorded)."""
    if not os.path.isfile(path):
        fail(f"{path}: file missing")
        return None
    reader = vtkXMLImageDataReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode() != 0:
        fail(f"{path}: VTK reader error code {reader.GetErrorCode()}")
        return None
    return reader.GetOutput()


def frames_of(pvd_path):
    """(time, path) of every DataSet of a .pvd collection."""
    root = ET.parse(pvd_path).getroot()
    if root.get("type") != "Collection":
        fail(f"{pvd_path}: a '{root.get('type')}', not a Collection")
    folder = os.path.dirname(pvd_path)
    return [(float(d.get("timestep")), os.path.join(folder, d.get("file")))
            for d in root.findall("./Collection/DataSet")]


def check_frame(path, time, dims, vtk_type=None):
    """Grid size, arrays and time of one frame; returns the image or None."""
    image = read(path)
    if image is None:
        return None
    if tuple(image.GetDimensions()) != tuple(n + 1 for n in dims):
        fail(f"{path}: point dimensions {image.GetDimensions()}, expected {tuple(n + 1 for n in dims)}")
    cells = dims[0] * dims[1] * dims[2]
    if image.GetNumberOfCells() != cells:
        fail(f"{path}: {image.GetNumberOfCells()} cells, expected {cells}")
    data = image.GetCellData()
    for name, components in (("pressure", 1), ("velocity", 3), ("porosity", 1)):
        array = data.GetArray(name)
        if array is None:
            fail(f"{path}: no cell-data array '{name}'")
            continue
        if array.GetNumberOfComponents() != components or array.GetNumberOfTuples() != cells:
            fail(f"{path}: '{name}' has {array.GetNumberOfTuples()} tuples of {array.GetNumberOfComponents()}, "
                 f"expected {cells} of {components}")
        if vtk_type is not None and array.GetDataType() != vtk_type:
            fail(f"{path}: '{name}' has VTK type {array.GetDataType()}, expected {vtk_type}")
    if image.GetPointData().GetNumberOfArrays() != 0:
        fail(f"{path}: point data present; the fluid fields are cell data")
    times = image.GetFieldData().GetArray("TimeValue")
    if times is None or times.GetValue(0) != time:
        fail(f"{path}: TimeValue {times and times.GetValue(0)}, expected {time} (the .pvd's)")
    return image


def value(image, name, cell, component=0):
    return image.GetCellData().GetArray(name).GetComponent(cell, component)


def check_known(folder, precision):
    """The frames of vti_writer_for_test against its formulas."""
    dims = (3, 2, 4)
    frames = frames_of(os.path.join(folder, "fluid.pvd"))
    expected_files = ["fluid_000000.vti", "fluid_000001.vti"]
    if [os.path.basename(f) for _, f in frames] != expected_files or [t for t, _ in frames] != [0.0, 0.25]:
        fail(f"{precision}: .pvd lists {frames}, expected {expected_files} at 0 and 0.25 s")
    vtk_type = VTK_DOUBLE if precision == "double" else VTK_FLOAT
    # The writer's values are these decimals rounded to its precision; VTK reads its text back
    # to that very value. Compared in double: exact for double, within half a float ulp for float.
    tol = 0.0 if precision == "double" else 6e-8
    for frame, (time, path) in enumerate(frames):
        image = check_frame(path, time, dims, vtk_type)
        if image is None:
            continue
        # Origin and spacing: the box's lower corner and the cell widths.
        for got, want, what in ((image.GetOrigin(), (-0.1, 0.2, 0.3), "origin"),
                                (image.GetSpacing(), (0.1, 0.1, 0.2), "spacing")):
            if not all(close(g, w, 1e-15 if precision == "double" else 5e-7) for g, w in zip(got, want)):
                fail(f"{path}: {what} {got}, expected {want}")
        rate = image.GetCellData().GetArray("porosity_rate")
        if rate is None:
            fail(f"{path}: no cell-data array 'porosity_rate'")
        mismatches = 0
        for k in range(dims[2]):
            for j in range(dims[1]):
                for i in range(dims[0]):
                    cell = i + dims[0] * (j + dims[1] * k)
                    # VTK's own cell id of the point (i, j, k) must be the same.
                    if image.ComputeCellId([i, j, k]) != cell:
                        fail(f"{path}: VTK numbers cell ({i}, {j}, {k}) {image.ComputeCellId([i, j, k])}, not {cell}")
                    want = {("pressure", 0): 1000 * k + 100 * j + 10 * i + 1.5 + frame,
                            ("velocity", 0): i + 0.25, ("velocity", 1): -j, ("velocity", 2): 0.125 * k - 1,
                            ("porosity", 0): 0.5 + 0.0625 * i + 0.125 * j + 0.03125 * k,
                            ("porosity_rate", 0): -0.5 * (i + 2 * j + 4 * k)}
                    for (name, component), w in want.items():
                        if name == "porosity_rate" and rate is None:
                            continue
                        got = value(image, name, cell, component)
                        if not close(got, w, tol):
                            mismatches += 1
                            if mismatches <= 10:
                                fail(f"{path}: {name}[{component}] of cell ({i}, {j}, {k}) is {got}, expected {w}")
    print(f"{precision}: {len(frames)} frames of {dims[0]} x {dims[1]} x {dims[2]} cells checked")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--writer", help="run this program with DIR first (vti_writer_for_test)")
    parser.add_argument("--pvd", help="check every frame of this fluid .pvd")
    parser.add_argument("--dims", type=int, nargs=3, metavar=("NX", "NY", "NZ"))
    parser.add_argument("--check", nargs=4, action="append", default=[],
                        metavar=("NAME[:COMPONENT]", "CELL", "VALUE", "RELTOL"))
    parser.add_argument("--range", nargs=3, action="append", default=[], metavar=("NAME", "LO", "HI"))
    parser.add_argument("dir", nargs="?")
    args = parser.parse_args()

    if args.writer:
        if not args.dir:
            parser.error("--writer needs DIR")
        shutil.rmtree(args.dir, ignore_errors=True)
        os.makedirs(args.dir)
        result = subprocess.run([args.writer, args.dir])
        if result.returncode != 0:
            print(f"FAILED: {args.writer} {args.dir} exited with {result.returncode}")
            return 1
        for precision in ("float", "double"):
            check_known(os.path.join(args.dir, precision), precision)
    elif args.pvd:
        if not args.dims:
            parser.error("--pvd needs --dims")
        frames = frames_of(args.pvd)
        if not frames:
            fail(f"{args.pvd}: no frames")
        image = None
        for time, path in frames:
            image = check_frame(path, time, args.dims)
        if image is not None:
            for name, cell, want, tol in args.check:
                array, _, component = name.partition(":")
                got = value(image, array, int(cell), int(component or 0))
                if not close(got, float(want), float(tol)):
                    fail(f"{frames[-1][1]}: {name} of cell {cell} is {got}, expected {want} (relative {tol})")
            for name, lo, hi in args.range:
                a = image.GetCellData().GetArray(name)
                values = [a.GetComponent(c, comp) for c in range(a.GetNumberOfTuples())
                          for comp in range(a.GetNumberOfComponents())]
                if not all(float(lo) <= v <= float(hi) for v in values):
                    fail(f"{frames[-1][1]}: {name} spans [{min(values)}, {max(values)}], not within [{lo}, {hi}]")
        print(f"{args.pvd}: {len(frames)} frames of {args.dims[0]} x {args.dims[1]} x {args.dims[2]} cells checked")
    else:
        parser.error("give --writer EXE DIR or --pvd FILE --dims NX NY NZ")
    if failures:
        print(f"FAILED: {len(failures)} mismatches")
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
