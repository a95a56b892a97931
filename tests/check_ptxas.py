"""The CUDA kernels' resource budget: reads ptxas's report (-Xptxas=-v) from the logs of the
CUDA instantiation targets (tests/cuda/ptxas_log.sh writes them), prints a table of registers,
stack and spills per kernel and architecture, and fails when a hot kernel uses stack or spills
beyond the budget below.

    check_ptxas.py <log>...

A kernel is named by its body: the functor of for_each_index, or the transform of a reduction
(`reduce(then_check<...>)`). Hot are all of sphere's kernels but the diagnostics (energies,
momentum, the search for a bad particle, the count of broken bonds, single-value kernels); the library's own kernels
(Thrust's and CUB's sorts and scans over plain keys) are listed but not judged.

BUDGET holds the hot kernels that still exceed zero (issue 10), each with the most stack and
spill bytes it may use; a kernel not in it may use none. Lower a budget when a kernel gets
leaner, and remove it at zero: the check also fails when a budget is larger than needed, so the
list stays the truth.
"""
import re
import subprocess
import sys

DIAGNOSTICS = ("particle_energy", "particle_momentum", "bad_particle", "set_kinematics", "bond_energy", "broken_bond")

# (pattern on the kernel's name, stack bytes, spill bytes): the largest over the architectures
# and precisions that match.
BUDGET = [
    # CUB's own reduction of a 24-byte type on sm_90 (vec3<double>: the sum of momentum(), a
    # diagnostic, whose transform runs in a kernel of its own, so the reduction's name does not
    # say whose it is).
    (r"^reduce1?\(vec3<double>\)$", 8, 8),
]


def demangle(names):
    out = subprocess.run(["c++filt"], input="\n".join(names), capture_output=True, text=True, check=True)
    return out.stdout.splitlines()


def first_argument(text, start):
    """The template argument that starts at text[start], up to its ',' or '>' at depth 0."""
    depth = 0
    for i in range(start, len(text)):
        c = text[i]
        if c in "<(":
            depth += 1
        elif c in ">)":
            if depth == 0:
                return text[start:i].strip()
            depth -= 1
        elif c == "," and depth == 0:
            return text[start:i].strip()
    return text[start:].strip()


def short(name):
    return name.replace("sphere::detail::", "").replace("sphere::", "")


def template_arguments(text, start):
    """The top-level template arguments of the list that opens at text[start] ('<')."""
    args, depth, begin = [], 0, start + 1
    for i in range(start + 1, len(text)):
        c = text[i]
        if c in "<(":
            depth += 1
        elif c in ">)":
            if depth == 0:
                args.append(text[begin:i].strip())
                return args
            depth -= 1
        elif c == "," and depth == 0:
            args.append(text[begin:i].strip())
            begin = i + 1
    return args


def body_name(demangled):
    """Short name of a kernel, or None for a library kernel over plain types."""
    key = "for_each_index_kernel<"
    if key in demangled:
        return short(first_argument(demangled, demangled.index(key) + len(key)))
    m = re.search(r"DeviceReduce(SingleTile)?Kernel<", demangled)
    if m:
        kind = "reduce1" if m.group(1) else "reduce"
        key = "transform_iterator<"
        if key in demangled:  # transform_reduce_into: the transform is the iterator's functor
            return f"{kind}({short(first_argument(demangled, demangled.index(key) + len(key)))})"
        ours = [a for a in template_arguments(demangled, m.end() - 1) if "sphere::" in a]
        if ours:  # thrust::transform_reduce: the transform is the last argument
            return f"{kind}({short(ours[-1])})"
    if "sphere::" in demangled:
        return short(re.sub(r"\s+", " ", demangled))
    return None


def parse(logs):
    rows = []
    for log in logs:
        entry = arch = None
        for line in open(log, errors="replace"):
            m = re.search(r"Compiling entry function '([^']+)' for '(sm_\d+)'", line)
            if m:
                entry, arch = m.groups()
                continue
            m = re.search(r"Function properties for (\S+)", line)
            if m and m.group(1) != entry:
                entry = None  # a device function, not a kernel
                continue
            m = re.search(r"(\d+) bytes stack frame, (\d+) bytes spill stores, (\d+) bytes spill loads", line)
            if m and entry:
                stack, stores, loads = map(int, m.groups())
                rows.append({"mangled": entry, "arch": arch, "stack": stack, "spill": max(stores, loads),
                             "stores": stores, "loads": loads})
                continue
            m = re.search(r"Used (\d+) registers", line)
            if m and entry and rows and rows[-1]["mangled"] == entry and "regs" not in rows[-1]:
                rows[-1]["regs"] = int(m.group(1))
                entry = None
    for row, name in zip(rows, demangle([r["mangled"] for r in rows])):
        row["name"] = body_name(name)
    return rows


def main(logs):
    rows = parse(logs)
    if not rows:
        print("no ptxas report in", " ".join(logs), "(compiled without -Xptxas=-v?)")
        return 1
    problems = []
    used = {i: (0, 0) for i in range(len(BUDGET))}
    print(f"{'kernel':<100} {'arch':<6} {'regs':>4} {'stack':>5} {'spill st/ld':>11}  judged")
    for r in sorted(rows, key=lambda r: (r["name"] or "~", r["arch"])):
        name = r["name"]
        hot = name is not None and not any(d in name for d in DIAGNOSTICS)
        if name is not None:
            print(f"{name[:100]:<100} {r['arch']:<6} {r.get('regs', 0):>4} {r['stack']:>5} "
                  f"{r['stores']:>5}/{r['loads']:<5}  {'hot' if hot else 'diagnostic'}")
        if not hot:
            continue
        allowed = (0, 0)
        for i, (pattern, stack, spill) in enumerate(BUDGET):
            if re.search(pattern, name):
                allowed = (stack, spill)
                used[i] = (max(used[i][0], r["stack"]), max(used[i][1], r["spill"]))
                break
        if r["stack"] > allowed[0] or r["spill"] > allowed[1]:
            problems.append(f"{name} ({r['arch']}): {r['stack']} B stack, {r['spill']} B spills; "
                            f"the budget is {allowed[0]} B and {allowed[1]} B")
    for i, (pattern, stack, spill) in enumerate(BUDGET):
        if used[i] != (stack, spill):
            problems.append(f"budget '{pattern}' allows {stack} B stack and {spill} B spills, its kernels use "
                            f"{used[i][0]} B and {used[i][1]} B: lower it (or remove it at zero)")
    print(f"{len(rows)} kernels, {sum(1 for r in rows if r['name'])} of sphere's; {len(problems)} over budget")
    for p in problems:
        print("OVER BUDGET:", p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
