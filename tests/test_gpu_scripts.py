#!/usr/bin/python3
"""Test of the two helpers of scripts/gpu-check.sh, which run only on a GPU machine:

    python3 tests/test_gpu_scripts.py SCRIPTS_DIR DATA_DIR

scripts/compare_series.py on synthetic CSV series (equal, within and over the tolerance, and
inputs it must refuse with status 2 and a message naming the problem), and
scripts/ncu_table.py on tests/data/ncu_report_sample.txt (two kernels of a real Nsight
Compute report of bench/bed_cuda at 1e6 particles, docs/gpu-results.md) and on a report without
kernels. Exits with status 1 on the first failure. Standard library only.
"""
import os
import subprocess
import sys
import tempfile


def fail(message):
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def run(script, *args):
    r = subprocess.run([sys.executable, script, *args], capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr


def write(path, text):
    with open(path, "w") as f:
        f.write(text)
    return path


def check_compare(script, folder):
    header = "time_s,x_m,force_N\n"
    rows = ["0,1.0,0\n", "1e-4,1.5,20\n", "2e-4,2.0,40\n"]
    ref = write(os.path.join(folder, "ref.csv"), header + "".join(rows))
    same = write(os.path.join(folder, "same.csv"), header + "".join(rows))
    # force off by 4e-6 of its largest value (40 N): within 1e-5, over 1e-6
    near = write(os.path.join(folder, "near.csv"), header + rows[0] + rows[1] + "2e-4,2.0,40.00016\n")

    code, out, err = run(script, "1e-9", ref, same)
    if code != 0 or "largest difference 0.00e+00" not in out:
        fail(f"equal series: status {code}, output {out!r} {err!r}")
    code, out, err = run(script, "1e-5", ref, near)
    if code != 0 or "4.00e-06" not in out or "(force_N)" not in out or "within" not in out:
        fail(f"series 4e-6 apart, tolerance 1e-5: status {code}, output {out!r} {err!r}")
    code, out, err = run(script, "1e-6", ref, near)
    if code != 1 or "OVER" not in out or "(force_N)" not in out:
        fail(f"series 4e-6 apart, tolerance 1e-6: status {code} (expected 1), output {out!r} {err!r}")

    short = write(os.path.join(folder, "short.csv"), header + rows[0])
    other_columns = write(os.path.join(folder, "columns.csv"), "time_s,x_m,torque_N_m\n" + "".join(rows))
    not_number = write(os.path.join(folder, "nan.csv"), header + rows[0] + "1e-4,abc,20\n" + rows[2])
    ragged = write(os.path.join(folder, "ragged.csv"), header + rows[0] + "1e-4,1.5\n" + rows[2])
    for other, words in ((short, "3 and 1 rows"), (other_columns, "different columns"),
                         (not_number, "nan.csv:3: a value that is not a number"),
                         (ragged, "ragged.csv:3: 2 values for 3 columns"),
                         (os.path.join(folder, "missing.csv"), "missing.csv")):
        code, out, err = run(script, "1e-5", ref, other)
        if code != 2 or words not in err or "Traceback" in err:
            fail(f"{os.path.basename(other)}: status {code} (expected 2), stderr {err!r} (expected {words!r})")


def check_ncu(script, sample, folder):
    code, out, err = run(script, sample)
    if code != 0:
        fail(f"ncu_table on the sample: status {code}, {err!r}")
    rows = {line.split("|")[1].strip(): [c.strip() for c in line.split("|")[2:-1]]
            for line in out.splitlines() if line.startswith("| `")}
    expected = {
        # launches, mean time (ms), TB/s, DRAM, issue slots, registers, occupancy
        "`gather_pair_results`": ["1", "0.371", "2.81", "58%", "6%", "32", "100%, 85%"],
        "`evaluate_owned_pairs`": ["1", "1.220", "1.07", "22%", "14%", "92", "25%, 23%"],
    }
    if rows != expected:
        fail(f"ncu_table rows {rows}, expected {expected}")
    empty = write(os.path.join(folder, "empty.txt"), "==PROF== Disconnected from process 1\n")
    code, out, err = run(script, empty)
    if code != 2 or "no kernel in the report" not in err:
        fail(f"ncu_table on a report without kernels: status {code}, {err!r}")


def main(argv):
    if len(argv) != 3:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    scripts, data = argv[1], argv[2]
    with tempfile.TemporaryDirectory() as folder:
        check_compare(os.path.join(scripts, "compare_series.py"), folder)
        check_ncu(os.path.join(scripts, "ncu_table.py"), os.path.join(data, "ncu_report_sample.txt"), folder)
    print("gpu scripts: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
