#!/usr/bin/python3
"""Test of scripts/plot_bond_rose.py: /usr/bin/python3 tests/test_plot_bond_rose.py PATH/TO/plot_bond_rose.py

Writes bonds VTK files in the layout of sphere::write_bonds_vtu into a temporary folder, checks
the trend and plunge the script computes against hand values (as sphere::orientation_of gives
them, tests/test_bonds.cpp), runs the script and checks the PNG it writes, and that malformed
files exit with status 2, name the file, print no traceback and write nothing. Exits with
status 1 on the first failure.
"""
import importlib.util
import os
import subprocess
import sys
import tempfile

import matplotlib
matplotlib.use("Agg")
import matplotlib.image  # noqa: E402

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def fail(message):
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def bonds_vtu(path, axes, cells=None, name="axis"):
    cells = len(axes) if cells is None else cells
    values = "\n".join(f"          {x} {y} {z}" for x, y, z in axes)
    with open(path, "w") as f:
        f.write(f"""<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="{2 * len(axes)}" NumberOfCells="{cells}">
      <CellData Scalars="stretch" Vectors="force">
        <DataArray type="Float64" Name="{name}" NumberOfComponents="3" format="ascii">
{values}
        </DataArray>
      </CellData>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
""")


def main(script):
    spec = importlib.util.spec_from_file_location("plot_bond_rose", script)
    rose = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(rose)
    # Trend clockwise from +y, plunge below the horizontal, axes taken pointing down.
    expected = [((0, 1, 0), (0, 0)), ((-1, 0, 0), (90, 0)), ((1, 1, -2 ** 0.5), (45, 45)),
                ((1, 1, 2 ** 0.5), (225, 45)), ((0, 0, 1), (0, 90))]
    got = rose.trend_plunge([a for a, _ in expected])
    for (axis, (trend, plunge)), (t, p) in zip(expected, got):
        if abs(t - trend) > 1e-9 or abs(p - plunge) > 1e-9:
            fail(f"axis {axis}: trend {t}, plunge {p}; expected {trend}, {plunge}")
    print("ok: trend and plunge")

    with tempfile.TemporaryDirectory() as folder:
        good = os.path.join(folder, "bonds.vtu")
        bonds_vtu(good, [a for a, _ in expected] * 20)
        out = os.path.join(folder, "figures")
        result = subprocess.run([sys.executable, script, good, "--out", out], capture_output=True, text=True,
                                timeout=120)
        if result.returncode != 0:
            fail(f"exit status {result.returncode}: {result.stderr}")
        target = os.path.join(out, "bonds-rose.png")
        if result.stdout.strip() != target or not os.path.exists(target):
            fail(f"printed {result.stdout!r}, expected {target}")
        with open(target, "rb") as f:
            if f.read(8) != PNG_SIGNATURE:
                fail(f"{target} is not a PNG")
        if matplotlib.image.imread(target).shape[1] <= 300:
            fail(f"{target} is too small")
        print("ok: bonds-rose.png")

        bad = os.path.join(folder, "bad")
        os.makedirs(bad)
        cases = {
            "notxml.vtu": lambda p: open(p, "w").write("not xml"),
            "noaxis.vtu": lambda p: bonds_vtu(p, [(1, 0, 0)], name="force"),
            "short.vtu": lambda p: bonds_vtu(p, [(1, 0, 0)], cells=2),
        }
        for name, make in cases.items():
            path = os.path.join(bad, name)
            make(path)
            result = subprocess.run([sys.executable, script, path], capture_output=True, text=True, timeout=120)
            if result.returncode != 2 or name not in result.stderr or "Traceback" in result.stderr:
                fail(f"{name}: status {result.returncode}, stderr {result.stderr!r}")
            if any(f.endswith(".png") for f in os.listdir(bad)):
                fail(f"{name}: a figure was written for a bad file")
            print(f"ok: {name}: {result.stderr.strip()}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        fail("usage: test_plot_bond_rose.py PATH/TO/plot_bond_rose.py")
    main(sys.argv[1])
