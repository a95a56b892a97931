#!/usr/bin/python3
"""Rose plot of the bonds' orientations (the seeds' bondsRose) from a bonds VTK file.

Usage: /usr/bin/python3 scripts/plot_bond_rose.py BONDS.vtu [--out DIR] [--format png|pdf]
       [--sectors N]

BONDS.vtu is what sphere::write_bonds_vtu writes (docs/physics.md, "Bonds"): one line cell per
intact bond with the cell data `axis` (m, from particle i's centre to j's, nearest image).
Each axis is taken pointing downwards (+z up) and given as trend (degrees clockwise from +y,
the north, to its horizontal projection, 0-360) and plunge (degrees below the horizontal,
0-90), as sphere::orientation_of does.

Writes DIR/bonds-rose.<format> (default DIR: the file's folder, format png) and prints its
path: the trends as a rose of N sectors (default 36) and the plunges as a histogram of 9 bins.
Errors (unreadable or malformed file, no `axis` data) print one message naming the file to
stderr and exit with status 2, before anything is written.
"""
import argparse
import math
import os
import sys
import xml.etree.ElementTree as ElementTree

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


class RoseError(Exception):
    """A problem with the input, reported as `plot_bond_rose: <message>` and exit status 2."""


def read_axes(path):
    """The bond axes of a bonds .vtu file: an (n, 3) array."""
    name = os.path.basename(path)
    try:
        root = ElementTree.parse(path).getroot()
    except (OSError, ElementTree.ParseError) as e:
        raise RoseError(f"{name}: cannot read it as VTK XML: {e}")
    piece = root.find("./UnstructuredGrid/Piece")
    if piece is None:
        raise RoseError(f"{name}: no UnstructuredGrid piece (not a bonds file of write_bonds_vtu)")
    cells = int(piece.get("NumberOfCells", "-1"))
    for array in piece.findall("./CellData/DataArray"):
        if array.get("Name") == "axis":
            try:
                values = np.array([float(v) for v in (array.text or "").split()])
            except ValueError as e:
                raise RoseError(f"{name}: the axis data are not numbers: {e}")
            if cells < 0 or values.size != 3 * cells:
                raise RoseError(f"{name}: {values.size} axis values for {cells} bonds (3 each)")
            return values.reshape(cells, 3)
    raise RoseError(f"{name}: no cell data 'axis' (written by sphere::write_bonds_vtu)")


def trend_plunge(axes):
    """Trend and plunge (degrees) of each axis, taken pointing downwards."""
    out = []
    for x, y, z in axes:
        if z > 0 or (z == 0 and (x < 0 or (x == 0 and y < 0))):
            x, y, z = -x, -y, -z
        trend = math.degrees(math.atan2(x, y)) % 360.0
        out.append((trend, math.degrees(math.atan2(-z, math.hypot(x, y)))))
    return np.array(out).reshape(-1, 2)


def plot(axes, sectors, target):
    angles = trend_plunge(axes)
    figure = plt.figure(figsize=(10, 4.5))
    rose = figure.add_subplot(1, 2, 1, projection="polar")
    rose.set_theta_zero_location("N")
    rose.set_theta_direction(-1)
    counts, edges = np.histogram(angles[:, 0], bins=sectors, range=(0.0, 360.0))
    rose.bar(np.radians(edges[:-1]), counts, width=np.radians(360.0 / sectors), align="edge",
             edgecolor="black", linewidth=0.5)
    rose.set_title(f"trend of {len(angles)} bonds")
    plunge = figure.add_subplot(1, 2, 2)
    plunge.hist(angles[:, 1], bins=9, range=(0.0, 90.0), edgecolor="black", linewidth=0.5)
    plunge.set_xlabel("plunge (degrees below horizontal)")
    plunge.set_ylabel("bonds")
    figure.tight_layout()
    figure.savefig(target)
    plt.close(figure)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("bonds")
    parser.add_argument("--out")
    parser.add_argument("--format", choices=["png", "pdf"], default="png")
    parser.add_argument("--sectors", type=int, default=36)
    args = parser.parse_args(argv)
    try:
        if args.sectors < 1:
            raise RoseError(f"{os.path.basename(args.bonds)}: --sectors {args.sectors}: at least 1")
        axes = read_axes(args.bonds)
        out = args.out or os.path.dirname(os.path.abspath(args.bonds))
        os.makedirs(out, exist_ok=True)
        target = os.path.join(out, f"bonds-rose.{args.format}")
        plot(axes, args.sectors, target)
    except RoseError as e:
        print(f"plot_bond_rose: {e}", file=sys.stderr)
        return 2
    print(target)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
