#!/usr/bin/python3
"""Plot a sphere CSV time series (docs/io.md, "CSV time series") as PNG figures.

Usage: /usr/bin/python3 scripts/plot_series.py SERIES.csv [--out DIR]

The CSV has a header line of `name_unit` columns and rows of numbers: every CSV the project
writes (the examples' series.csv, collision.csv, fluid_consolidation's terzaghi.csv). Columns:
  required   time_s
  energy     time_s, kinetic_J, rotational_J, potential_J, elastic_J, dissipated_visc_J,
             dissipated_fric_J, boundary_work_J, total_J
  terzaghi   time_s, settlement_m, terzaghi_settlement_m, excess_p_bottom_Pa,
             terzaghi_excess_p_bottom_Pa (fluid_consolidation's terzaghi.csv)
  walls      wall_<face>_position_m, wall_<face>_force_N (face: xlo xhi ylo yhi zlo zhi);
             normal_stress_Pa
  porosity   porosity, void_ratio (derived from porosity when absent)
  shear      shear_strain, shear_stress_Pa, friction_coefficient, dilation_m
Every other column is drawn against time in series.png.

Figures, written to DIR (default: the CSV's folder), one printed line (the path) each:
  energy.png    energy budget and the balance total_J - total_J[0] against time (when the
                energy columns exist)
  walls.png     positions and forces of the moving walls, normal stress (when wall columns exist)
  porosity.png  porosity and void ratio against time (when `porosity` exists)
  shear.png     shear stress, friction coefficient and dilation against shear strain
                (when `shear_strain` exists)
  terzaghi.png  settlement and the bottom's excess pore pressure against Terzaghi's (when the
                Terzaghi columns exist)
  series.png    one panel per column that none of the figures above shows, against time
                (when there is such a column)
Errors (unreadable file, bad header or row, no rows) print one message naming the file to
stderr and exit with status 2, before any figure is written.
"""
import argparse
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ENERGY_COLUMNS = ["time_s", "kinetic_J", "rotational_J", "potential_J", "elastic_J",
                  "dissipated_visc_J", "dissipated_fric_J", "boundary_work_J", "total_J"]
TERZAGHI_COLUMNS = ["time_s", "settlement_m", "terzaghi_settlement_m", "excess_p_bottom_Pa",
                    "terzaghi_excess_p_bottom_Pa"]
FACES = ["xlo", "xhi", "ylo", "yhi", "zlo", "zhi"]


class SeriesError(Exception):
    """A problem with the input, reported as `plot_series: <message>` and exit status 2."""


def read_series(path):
    """Returns {column name: numpy array} for the CSV at `path`; raises SeriesError."""
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except (OSError, UnicodeDecodeError) as e:
        raise SeriesError(f"cannot read '{path}': {getattr(e, 'strerror', None) or e}")
    if not lines or not lines[0].strip():
        raise SeriesError(f"'{path}' is empty (no header line)")
    names = [n.strip() for n in lines[0].split(",")]
    if len(set(names)) != len(names):
        raise SeriesError(f"'{path}' line 1: repeated column name in the header")
    if "time_s" not in names:
        raise SeriesError(f"'{path}' line 1: header lacks the column time_s")
    rows = []
    for number, line in enumerate(lines[1:], start=2):
        values = line.split(",")
        if len(values) != len(names):
            raise SeriesError(f"'{path}' line {number}: expected {len(names)} values, "
                              f"found {len(values) if line.strip() else 0}")
        try:
            rows.append([float(v) for v in values])
        except ValueError:
            bad = next(v for v in values if not _is_number(v))
            raise SeriesError(f"'{path}' line {number}: '{bad.strip()}' is not a number") from None
    if not rows:
        raise SeriesError(f"'{path}' has a header but no data rows")
    data = np.array(rows, dtype=float)
    return {name: data[:, c] for c, name in enumerate(names)}


def _is_number(text):
    try:
        float(text)
        return True
    except ValueError:
        return False


def plot_energy(s):
    t = s["time_s"]
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(9, 7),
                                      gridspec_kw={"height_ratios": [3, 1]})
    curves = [("kinetic + rotational", s["kinetic_J"] + s["rotational_J"]),
              ("potential - initial", s["potential_J"] - s["potential_J"][0]),
              ("elastic", s["elastic_J"]),
              ("viscous dissipation", s["dissipated_visc_J"]),
              ("frictional dissipation", s["dissipated_fric_J"]),
              ("boundary work", s["boundary_work_J"])]
    for label, y in curves:
        top.plot(t, y, label=label)
    top.set_ylabel("energy [J]")
    top.legend(fontsize="small")
    bottom.plot(t, s["total_J"] - s["total_J"][0], color="k", label="total - initial total")
    bottom.set_ylabel("balance [J]")
    bottom.set_xlabel("time [s]")
    bottom.legend(fontsize="small")
    fig.suptitle("Energy budget")
    return fig


def plot_walls(s):
    t = s["time_s"]
    faces = [f for f in FACES if f"wall_{f}_position_m" in s]
    moving = [f for f in faces if np.any(s[f"wall_{f}_position_m"] != s[f"wall_{f}_position_m"][0])]
    with_stress = "normal_stress_Pa" in s
    fig, axes = plt.subplots(3 if with_stress else 2, 1, sharex=True, figsize=(9, 9 if with_stress else 7))
    for f in moving:
        axes[0].plot(t, s[f"wall_{f}_position_m"], label=f)
    if moving:
        axes[0].legend(fontsize="small", title="wall")
    else:
        axes[0].text(0.5, 0.5, "no wall moves", ha="center", va="center", transform=axes[0].transAxes)
    axes[0].set_ylabel("position [m]")
    # The forces of the moving walls; when none moves, those of every wall.
    for f in moving or faces:
        if f"wall_{f}_force_N" in s:
            axes[1].plot(t, s[f"wall_{f}_force_N"], label=f)
    axes[1].set_ylabel("force along axis [N]")
    if axes[1].lines:
        axes[1].legend(fontsize="small", title="wall")
    if with_stress:
        axes[2].plot(t, s["normal_stress_Pa"] / 1e3, color="k", label="normal stress")
        axes[2].set_ylabel("normal stress [kPa]")
        axes[2].legend(fontsize="small")
    axes[-1].set_xlabel("time [s]")
    fig.suptitle("Walls")
    return fig


def plot_porosity(s):
    t = s["time_s"]
    void = s["void_ratio"] if "void_ratio" in s else s["porosity"] / (1 - s["porosity"])
    fig, ax = plt.subplots(figsize=(9, 5))
    ax.plot(t, s["porosity"], color="C0", label="porosity")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("porosity [-]")
    twin = ax.twinx()
    twin.plot(t, void, color="C1", linestyle="--", label="void ratio")
    twin.set_ylabel("void ratio [-]")
    ax.legend(handles=ax.lines + twin.lines, fontsize="small")
    fig.suptitle("Porosity")
    return fig


def plot_shear(s):
    gamma = s["shear_strain"]
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(9, 7))
    handles = []
    if "shear_stress_Pa" in s:
        handles += top.plot(gamma, s["shear_stress_Pa"] / 1e3, color="C0", label="shear stress")
    top.set_ylabel("shear stress [kPa]")
    if "friction_coefficient" in s:
        twin = top.twinx()
        handles += twin.plot(gamma, s["friction_coefficient"], color="C1", linestyle="--",
                             label="friction coefficient")
        twin.set_ylabel("friction coefficient [-]")
    if handles:
        top.legend(handles=handles, fontsize="small")
    if "dilation_m" in s:
        bottom.plot(gamma, s["dilation_m"] * 1e3, color="C2", label="dilation")
        bottom.legend(fontsize="small")
    bottom.set_ylabel("dilation [mm]")
    bottom.set_xlabel("shear strain [-]")
    fig.suptitle("Shear")
    return fig


def plot_terzaghi(s):
    t = s["time_s"]
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(9, 7))
    top.plot(t, s["settlement_m"] * 1e3, color="C0", label="settlement")
    top.plot(t, s["terzaghi_settlement_m"] * 1e3, color="C0", linestyle="--", label="Terzaghi")
    top.set_ylabel("settlement [mm]")
    top.legend(fontsize="small")
    bottom.plot(t, s["excess_p_bottom_Pa"] / 1e3, color="C1", label="excess pore pressure, bottom")
    bottom.plot(t, s["terzaghi_excess_p_bottom_Pa"] / 1e3, color="C1", linestyle="--", label="Terzaghi")
    bottom.set_ylabel("excess pore pressure [kPa]")
    bottom.set_xlabel("time after the load [s]")
    bottom.legend(fontsize="small")
    fig.suptitle("Consolidation against Terzaghi")
    return fig


def shown_elsewhere(s):
    """The columns that energy.png, walls.png, porosity.png, shear.png and terzaghi.png draw."""
    shown = {"time_s"}
    if all(c in s for c in ENERGY_COLUMNS):
        shown.update(ENERGY_COLUMNS)
    if all(c in s for c in TERZAGHI_COLUMNS):
        shown.update(TERZAGHI_COLUMNS)
    if any(name.startswith("wall_") for name in s):
        shown.update({f"wall_{f}_{q}" for f in FACES for q in ("position_m", "force_N")})
        shown.add("normal_stress_Pa")
    if "porosity" in s:
        shown.update({"porosity", "void_ratio"})
    if "shear_strain" in s:
        shown.update({"shear_strain", "shear_stress_Pa", "friction_coefficient", "dilation_m"})
    return shown


def plot_other(s):
    """One panel per column that no other figure shows, against time, three panels a row."""
    shown = shown_elsewhere(s)
    columns = [c for c in s if c not in shown]
    rows = (len(columns) + 2) // 3
    fig, axes = plt.subplots(rows, min(3, len(columns)), sharex=True, squeeze=False,
                             figsize=(4 * min(3, len(columns)) + 1, 2.6 * rows + 0.8))
    for k, name in enumerate(columns):
        ax = axes[k // 3][k % 3]
        ax.plot(s["time_s"], s[name], lw=1)
        ax.set_title(name, fontsize="small")
    for k in range(len(columns), rows * axes.shape[1]):
        axes[k // 3][k % 3].set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    fig.tight_layout()
    return fig


def main(argv=None):
    parser = argparse.ArgumentParser(description="Plot a sphere CSV time series as PNG figures.")
    parser.add_argument("csv", help="the CSV time series")
    parser.add_argument("--out", help="folder for the figures (default: the CSV's folder)")
    args = parser.parse_args(argv)
    out = args.out if args.out is not None else (os.path.dirname(args.csv) or ".")
    try:
        s = read_series(args.csv)
        figures = []
        if all(c in s for c in ENERGY_COLUMNS):
            figures.append(("energy.png", plot_energy))
        if all(c in s for c in TERZAGHI_COLUMNS):
            figures.append(("terzaghi.png", plot_terzaghi))
        if any(name.startswith("wall_") for name in s):
            figures.append(("walls.png", plot_walls))
        if "porosity" in s:
            figures.append(("porosity.png", plot_porosity))
        if "shear_strain" in s:
            figures.append(("shear.png", plot_shear))
        if any(c not in shown_elsewhere(s) for c in s):
            figures.append(("series.png", plot_other))
        try:
            os.makedirs(out, exist_ok=True)
        except OSError as e:
            raise SeriesError(f"cannot create the output folder '{out}' for '{args.csv}': {e.strerror}")
        for name, plot in figures:
            path = os.path.join(out, name)
            fig = plot(s)
            try:
                fig.savefig(path, dpi=100)
            except OSError as e:
                raise SeriesError(f"cannot write '{path}' (from '{args.csv}'): {e.strerror or e}")
            finally:
                plt.close(fig)
            print(path)
    except SeriesError as e:
        print(f"plot_series: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
