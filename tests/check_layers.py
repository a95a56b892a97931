"""The layers of include/sphere/ hold: every header's `#include "..."` lines point only down
the layer table of docs/architecture.md (section "Layers"), and the table says the truth.

    check_layers.py <repository root>

The table's rows are the layers, lowest first. The first column names a row's members (`core/`
for a folder, `simulation.cuh` for a top-level header); the row is called by its first member
without `/` or `.cuh`. The last column lists, comma-separated, the rows its headers include
("nothing" for none, "all" for every row above). A header may include headers of its own row
and of the rows its row lists; every listed row must lie above it, and must really be included
(so the table cannot claim more than the code does). Dispatch on the execution policy
(`is_same<Policy, ...>`) belongs in exec/ alone, and CUDA-only code (CUDA_ONLY below) in core/
and exec/ alone. Exits 1 with one line per violation.
"""
import pathlib
import re
import sys


# What compiles only under nvcc: the compiler's macros, the CUDA runtime, Thrust and CUB.
CUDA_ONLY = r"__CUDACC__|__CUDA_ARCH__|cuda_runtime|\bcub::|\bthrust::|<cub/|<thrust/"


def parse_table(architecture):
    text = architecture.read_text()
    section = text.split("## Layers", 1)[1].split("\n## ", 1)[0]
    rows = []
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.startswith("|") or len(cells) < 3 or set(cells[0]) <= set("-: "):
            continue
        members = re.findall(r"`([^`]+)`", cells[0])
        if not members:  # the header row
            continue
        name = members[0].rstrip("/").removesuffix(".cuh")
        deps = [d.strip() for d in cells[-1].split(",") if d.strip()]
        rows.append((name, members, deps))
    return rows


def row_of(header, rows):
    """The row of a header path relative to include/sphere/, or None."""
    first = header.parts[0] + "/" if len(header.parts) > 1 else header.name
    for name, members, _ in rows:
        if first in members:
            return name
    return None


def main(root):
    root = pathlib.Path(root)
    include = root / "include" / "sphere"
    rows = parse_table(root / "docs" / "architecture.md")
    if not rows:
        print("docs/architecture.md: no layer table under '## Layers'")
        return 1
    rank = {name: i for i, (name, _, _) in enumerate(rows)}
    problems = []
    allowed = {}
    for name, _, deps in rows:
        if deps == ["nothing"]:
            deps = []
        elif deps == ["all"]:
            deps = [n for n, _, _ in rows[: rank[name]]]
        for d in deps:
            if d not in rank:
                problems.append(f"docs/architecture.md: row '{name}' depends on '{d}', which is not a row")
            elif rank[d] >= rank[name]:
                problems.append(f"docs/architecture.md: row '{name}' depends on '{d}', which is not above it")
        allowed[name] = set(deps)

    used = {name: set() for name in rank}
    for path in sorted(include.rglob("*.cuh")):
        header = path.relative_to(include)
        own = row_of(header, rows)
        if own is None:
            problems.append(f"include/sphere/{header}: in no row of the layer table")
            continue
        source = path.read_text()
        for number, line in enumerate(source.splitlines(), 1):
            match = re.match(r'\s*#\s*include\s+"([^"]+)"', line)
            if match:
                target = (path.parent / match.group(1)).resolve()
                try:
                    target_header = target.relative_to(include.resolve())
                except ValueError:
                    problems.append(f"include/sphere/{header}:{number}: includes {match.group(1)}, outside include/sphere/")
                    continue
                to = row_of(target_header, rows)
                if to is None or to == own:
                    continue
                used[own].add(to)
                if to not in allowed[own]:
                    problems.append(f"include/sphere/{header}:{number}: includes {target_header} (row '{to}'), "
                                    f"which row '{own}' does not list")
            if own != "exec" and re.search(r"is_same(_v)?\s*<\s*Policy\b", line):
                problems.append(f"include/sphere/{header}:{number}: dispatches on the policy outside exec/")
            if own not in ("core", "exec") and re.search(CUDA_ONLY, line):
                problems.append(f"include/sphere/{header}:{number}: CUDA-only code outside core/ and exec/ "
                                "(tests/CMakeLists.txt compiles only those headers one by one with nvcc)")
    for name, _, deps in rows:
        if deps not in (["all"], ["nothing"]):
            for d in sorted(allowed[name] - used[name]):
                problems.append(f"docs/architecture.md: row '{name}' lists '{d}', which none of its headers includes")
    for p in problems:
        print(p)
    print(f"{len(rows)} layers, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
