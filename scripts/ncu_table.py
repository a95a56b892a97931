#!/usr/bin/python3
"""Summarises Nsight Compute's text report (`ncu --section SpeedOfLight --section
MemoryWorkloadAnalysis --section Occupancy --section LaunchStats --section
ComputeWorkloadAnalysis ...`, as scripts/gpu-check.sh runs it) into a markdown table: one row
per kernel body, named by the sphere kernels in its template arguments (the wrappers
store_values, then_check, unless_halted, by_rank and both left out), with its launches, mean
duration, memory throughput, DRAM and issue-slot shares, registers and occupancy.

    ncu_table.py REPORT.txt

Exits with status 2 when the report cannot be read or holds no kernel. Standard library only.
"""
import re
import sys

WRAPPERS = {"for_each_index_kernel", "store_values", "then_check", "unless_halted", "by_rank", "both"}
# a kernel's heading: its name and parameters, grid x block, context, stream, device
KERNEL = re.compile(r"^\s{2}(\S.*?) \(\d+, \d+, \d+\)x\(\d+, \d+, \d+\), Context \d+")
METRIC = re.compile(r"^\s{4}(\S.*?\S)\s{2,}(\S+)\s+([\d.,]+)\s*$")
UNIT_MS = {"ns": 1e-6, "us": 1e-3, "usecond": 1e-3, "ms": 1.0, "msecond": 1.0, "s": 1e3, "second": 1e3}
UNIT_TBS = {"Gbyte/s": 1e-3, "Tbyte/s": 1.0, "Mbyte/s": 1e-6}


def label(kernel):
    """The sphere kernel bodies named in a demangled kernel, outermost first."""
    names = re.findall(r"(?<![:\w])([a-z_][a-z0-9_]*)<", kernel)
    return " + ".join(n for n in names if n not in WRAPPERS) or kernel


def parse(text):
    """{label: {"launches": n, "ms": [durations], metric: value}} in the report's order."""
    kernels = {}
    current = None
    for line in text.splitlines():
        k = KERNEL.match(line)
        if k:
            current = kernels.setdefault(label(k.group(1)), {"launches": 0, "ms": []})
            current["launches"] += 1
            continue
        m = METRIC.match(line)
        if not m or current is None:
            continue
        name, unit, value = m.group(1), m.group(2), float(m.group(3).replace(",", ""))
        if name == "Duration" and unit in UNIT_MS:
            current["ms"].append(value * UNIT_MS[unit])
        elif name == "Memory Throughput" and unit in UNIT_TBS:
            current["TB/s"] = value * UNIT_TBS[unit]
        elif name in ("DRAM Throughput", "Issue Slots Busy", "Theoretical Occupancy", "Achieved Occupancy") and unit == "%":
            current[name] = value
        elif name == "Registers Per Thread":
            current[name] = value
    return kernels


def table(kernels):
    def cell(k, key, form):
        return form.format(k[key]) if key in k else "-"

    rows = ["| kernel body | launches | mean time (ms) | memory (TB/s) | DRAM | issue slots busy | registers | occupancy: theoretical, achieved |",
            "|---|---|---|---|---|---|---|---|"]
    for name, k in kernels.items():
        mean = sum(k["ms"]) / len(k["ms"]) if k["ms"] else None
        rows.append(f"| `{name}` | {k['launches']} | {'-' if mean is None else f'{mean:.3f}'} | "
                    f"{cell(k, 'TB/s', '{:.2f}')} | {cell(k, 'DRAM Throughput', '{:.0f}%')} | "
                    f"{cell(k, 'Issue Slots Busy', '{:.0f}%')} | {cell(k, 'Registers Per Thread', '{:.0f}')} | "
                    f"{cell(k, 'Theoretical Occupancy', '{:.0f}%')}, {cell(k, 'Achieved Occupancy', '{:.0f}%')} |")
    return "\n".join(rows)


def main(argv):
    if len(argv) != 2:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    try:
        with open(argv[1], errors="replace") as f:
            kernels = parse(f.read())
    except OSError as e:
        print(f"ncu_table: {argv[1]}: {e.strerror}", file=sys.stderr)
        return 2
    if not kernels:
        print(f"ncu_table: {argv[1]}: no kernel in the report", file=sys.stderr)
        return 2
    print(table(kernels))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
