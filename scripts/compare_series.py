#!/usr/bin/python3
"""Compares two CSV time series of the same run on two backends (scripts/gpu-check.sh: the
collision example's `--backend host` and `--backend cuda`).

    compare_series.py TOLERANCE REFERENCE.csv OTHER.csv

Both files must have the same header and the same number of rows. For each column, the
largest |difference| over the rows is taken relative to the column's largest |value| in
REFERENCE (absolute where that is 0). Prints the largest of these and its column, and exits
with status 1 when it exceeds TOLERANCE, with status 2 when the files cannot be compared
(missing, different columns or rows, a value that is not a number). Standard library only.
"""
import csv
import math
import sys


def read(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as e:
        raise ValueError(f"{path}: {e.strerror}") from None
    if not rows:
        raise ValueError(f"{path}: empty")
    header, body = rows[0], rows[1:]
    values = []
    for number, row in enumerate(body, 2):
        if len(row) != len(header):
            raise ValueError(f"{path}:{number}: {len(row)} values for {len(header)} columns")
        try:
            values.append([float(v) for v in row])
        except ValueError:
            raise ValueError(f"{path}:{number}: a value that is not a number") from None
    return header, values


def largest_difference(reference, other):
    """(relative difference, column) of the column that differs most."""
    header, a = reference
    header_b, b = other
    if header != header_b:
        raise ValueError("the files have different columns")
    if len(a) != len(b):
        raise ValueError(f"the files have {len(a)} and {len(b)} rows")
    worst = (0.0, header[0] if header else "")
    for k, name in enumerate(header):
        scale = max((abs(row[k]) for row in a), default=0.0)
        diff = max((abs(x[k] - y[k]) for x, y in zip(a, b)), default=0.0)
        if math.isnan(diff):
            return math.inf, name
        relative = diff / scale if scale > 0 else diff
        if relative > worst[0]:
            worst = (relative, name)
    return worst


def main(argv):
    if len(argv) != 4:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    try:
        tolerance = float(argv[1])
        difference, column = largest_difference(read(argv[2]), read(argv[3]))
    except ValueError as e:
        print(f"compare_series: {e}", file=sys.stderr)
        return 2
    verdict = "within" if difference <= tolerance else "OVER"
    print(f"largest difference {difference:.2e} of the column's largest value ({column}), {verdict} the tolerance {tolerance:g}")
    return 0 if difference <= tolerance else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
