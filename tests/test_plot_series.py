#!/usr/bin/python3
"""Test of scripts/plot_series.py: /usr/bin/python3 tests/test_plot_series.py PATH/TO/plot_series.py

Writes synthetic CSV series into a temporary folder, runs the script on them with this
interpreter and checks which PNG files it writes (valid PNGs, wider than 300 px) and which it
does not, and that each malformed input exits with status 2, names the file in its message,
prints no traceback and writes no PNG. Exits with status 1 on the first failure.
"""
import math
import os
import subprocess
import sys
import tempfile

import matplotlib
matplotlib.use("Agg")
import matplotlib.image  # noqa: E402

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
ENERGY = ["time_s", "kinetic_J", "rotational_J", "potential_J", "elastic_J",
          "dissipated_visc_J", "dissipated_fric_J", "boundary_work_J", "total_J"]
FIGURES = ["energy.png", "walls.png", "porosity.png", "shear.png", "terzaghi.png"]


def fail(message):
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def write_csv(path, columns, rows):
    with open(path, "w") as f:
        f.write(",".join(columns) + "\n")
        for row in rows:
            f.write(",".join(f"{v:.17g}" for v in row) + "\n")


def energy_row(i, n):
    t = 1e-4 * i
    kin, pot, ela = 1e-3 * math.exp(-i / n), -2e-3 * i / n, 5e-4 * (1 - math.exp(-i / n))
    visc, fric, work = 3e-4 * i / n, 2e-4 * i / n, 1e-5 * i / n
    total = 4.2e-3 + 1e-12 * math.sin(i)  # constant up to round-off
    return [t, kin, 0.1 * kin, pot, ela, visc, fric, work, total]


def consolidation(path, n=50):
    """A closed box whose top wall (zhi) moves down; porosity and normal stress."""
    columns = list(ENERGY)
    for face in ["xlo", "xhi", "ylo", "yhi", "zlo", "zhi"]:
        columns += [f"wall_{face}_position_m", f"wall_{face}_velocity_m/s", f"wall_{face}_force_N"]
    columns += ["porosity", "void_ratio", "normal_stress_Pa", "axial_strain"]
    rows = []
    for i in range(n):
        row = energy_row(i, n)
        z_top = 0.01 - 1e-5 * i
        for hi, speed, force in [(0.01, 0.0, 0.5), (0.01, 0.0, 0.5), (z_top, -0.1, 1.0 + 0.1 * i)]:
            row += [0.0, 0.0, -force, hi, speed, force]  # lower face fixed at 0, upper face
        phi = 0.45 - 0.001 * i
        row += [phi, phi / (1 - phi), 1e4 + 100 * i, 1e-3 * i]
        rows.append(row)
    write_csv(path, columns, rows)


def shear(path, n=60):
    """A periodic shear box (no wall columns) with the shear columns."""
    columns = ENERGY + ["shear_strain", "shear_stress_Pa", "friction_coefficient", "dilation_m",
                        "normal_stress_Pa"]
    rows = []
    for i in range(n):
        gamma = 0.005 * i
        tau = 5e3 * (1 - math.exp(-gamma / 0.03))
        rows.append(energy_row(i, n) + [gamma, tau, tau / 1e4, 2e-5 * math.tanh(gamma / 0.05), 1e4])
    write_csv(path, columns, rows)


def terzaghi(path, n=40):
    """fluid_consolidation's terzaghi.csv: no energy columns."""
    columns = ["time_s", "settlement_m", "terzaghi_settlement_m", "excess_p_bottom_Pa",
               "terzaghi_excess_p_bottom_Pa"]
    rows = []
    for i in range(n):
        t = 0.01 * i
        rows.append([t, 1e-3 * (1 - math.exp(-t / 0.1)), 1e-3 * (1 - math.exp(-t / 0.12)),
                     1e4 * math.exp(-t / 0.1), 1e4 * math.exp(-t / 0.12)])
    write_csv(path, columns, rows)


def run(script, *args):
    return subprocess.run([sys.executable, script, *args], capture_output=True, text=True, timeout=120)


def pngs(folder):
    if not os.path.isdir(folder):
        return []
    return sorted(name for name in os.listdir(folder) if name.endswith(".png"))


def check_png(path):
    with open(path, "rb") as f:
        if f.read(8) != PNG_SIGNATURE:
            fail(f"{path} does not start with the PNG signature")
    image = matplotlib.image.imread(path)
    if image.ndim != 3 or image.shape[1] <= 300:
        fail(f"{path}: unexpected image shape {image.shape}")


def check_figures(script, csv, out, expected, extra_args=()):
    result = run(script, csv, *extra_args)
    if result.returncode != 0:
        fail(f"{csv}: exit status {result.returncode}, stderr:\n{result.stderr}")
    if pngs(out) != sorted(expected):
        fail(f"{csv}: wrote {pngs(out)}, expected {sorted(expected)}")
    printed = result.stdout.split()
    if sorted(os.path.basename(p) for p in printed) != sorted(expected) \
            or not all(os.path.samefile(p, os.path.join(out, os.path.basename(p))) for p in printed):
        fail(f"{csv}: printed {printed!r}, expected the paths of {sorted(expected)}")
    for name in expected:
        check_png(os.path.join(out, name))
    print(f"ok: {os.path.basename(csv)} -> {', '.join(sorted(expected))}")


def check_error(script, csv, what, folder):
    result = run(script, csv)
    if result.returncode != 2:
        fail(f"{what}: exit status {result.returncode}, expected 2 (stderr: {result.stderr!r})")
    if os.path.basename(csv) not in result.stderr:
        fail(f"{what}: the message does not name the file: {result.stderr!r}")
    if "Traceback" in result.stderr:
        fail(f"{what}: a traceback instead of a message:\n{result.stderr}")
    if pngs(folder):
        fail(f"{what}: wrote {pngs(folder)} although the input is bad")
    print(f"ok: {what}: {result.stderr.strip()}")
    return result.stderr


def main():
    if len(sys.argv) != 2:
        print(f"usage: {sys.argv[0]} PATH/TO/plot_series.py", file=sys.stderr)
        return 2
    script = os.path.abspath(sys.argv[1])
    if not os.path.isfile(script):
        fail(f"no script at {script}")
    with tempfile.TemporaryDirectory(prefix="plot_series_test_") as tmp:
        # Consolidation: energy, walls and porosity, but no shear figure; default output folder.
        folder = os.path.join(tmp, "consolidation")
        os.mkdir(folder)
        consolidation(os.path.join(folder, "series.csv"))
        check_figures(script, os.path.join(folder, "series.csv"), folder,
                      ["energy.png", "walls.png", "porosity.png", "series.png"])

        # Shear: energy and shear (no wall columns, no porosity), the normal stress in series.png;
        # --out elsewhere.
        folder = os.path.join(tmp, "shear")
        os.mkdir(folder)
        out = os.path.join(tmp, "shear_figures", "nested")
        shear(os.path.join(folder, "shear.csv"))
        check_figures(script, os.path.join(folder, "shear.csv"), out, ["energy.png", "shear.png", "series.png"],
                      ["--out", out])
        if pngs(folder):
            fail(f"--out given, yet figures were written next to the CSV: {pngs(folder)}")
        # Terzaghi: the settlement and pressure figure alone (no energy columns needed).
        folder = os.path.join(tmp, "terzaghi")
        os.mkdir(folder)
        terzaghi(os.path.join(folder, "terzaghi.csv"))
        check_figures(script, os.path.join(folder, "terzaghi.csv"), folder, ["terzaghi.png"])

        # Any other CSV (the collision example's): every column against time in series.png.
        folder = os.path.join(tmp, "collision")
        os.mkdir(folder)
        write_csv(os.path.join(folder, "collision.csv"), ["time_s", "x1_m", "vz1_m_s", "overlap_m", "normal_force_N"],
                  [[1e-5 * i, 0.01 * i, -1 + 0.1 * i, max(0, 1e-4 * (i - 3)), 5.0 * i] for i in range(20)])
        check_figures(script, os.path.join(folder, "collision.csv"), folder, ["series.png"])

        # Errors: exit status 2, the file named, no PNG written.
        header = ",".join(ENERGY)
        good = ",".join(["1"] * len(ENERGY))
        cases = [
            ("missing time column", ",".join(ENERGY[1:]) + "\n" + ",".join(["1"] * 8) + "\n", "time_s"),
            ("ragged row", f"{header}\n{good}\n{good},7\n", "line 3"),
            ("non-numeric value", f"{header}\n{good}\n" + good.replace("1", "abc", 1) + "\n", "line 3"),
            ("no data rows", header + "\n", None),
            ("empty file", "", None),
        ]
        for number, (what, text, detail) in enumerate(cases):
            folder = os.path.join(tmp, f"error{number}")
            os.mkdir(folder)
            csv = os.path.join(folder, f"bad_{number}.csv")
            with open(csv, "w") as f:
                f.write(text)
            message = check_error(script, csv, what, folder)
            if detail and detail not in message:
                fail(f"{what}: the message does not mention {detail!r}: {message!r}")
        folder = os.path.join(tmp, "missing")
        os.mkdir(folder)
        check_error(script, os.path.join(folder, "does_not_exist.csv"), "missing file", folder)
    print("all plot_series checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
