"""Files written from Python: the particles as VTK (.vtu), the fluid's cells as a VTK image
(.vti), CSV series (the Recorder's with the C++ diagnostics columns, a Fluid's solver history,
any columns) read back to the last bit, and their errors."""

import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest

import sphere
from conftest import linear_settings
from test_fluid import lattice_bed


def arrays(path):
    """The DataArrays of an ASCII VTK XML file by name, as float arrays."""
    found = {}
    for a in ElementTree.parse(path).getroot().iter("DataArray"):
        found[a.get("Name")] = np.array(a.text.split(), dtype=np.float64)
    return found


def test_particles_as_vtk(precision, tmp_path):
    sim = lattice_bed(precision, layers=2, fixed=False, dt=0.0)
    sim.run(10)
    sim.write_vtk(tmp_path / "particles.vtu")
    got, snap = arrays(tmp_path / "particles.vtu"), sim.snapshot()
    # Written with the digits of the precision: every value reads back exactly.
    real = snap.positions.dtype
    assert np.array_equal(got["position"].reshape(-1, 3).astype(real), snap.positions)
    assert np.array_equal(got["velocity"].reshape(-1, 3).astype(real), snap.velocities)
    assert np.array_equal(got["radius"].astype(real), snap.radii)
    assert got["TimeValue"][0] == sim.time
    with pytest.raises(sphere.Error, match="no-such-folder"):
        sim.write_vtk(tmp_path / "no-such-folder" / "particles.vtu")


def test_fluid_cells_as_vtk_image(tmp_path):
    sim = lattice_bed("double")
    fluid = sphere.Fluid(sim, (2, 2, 6), sphere.FluidSettings(density=1000, top=sphere.FluidBoundary("pressure")))
    fluid.step(2)
    fluid.write_vtk(tmp_path / "fluid.vti")
    got = arrays(tmp_path / "fluid.vti")
    # The image's points run x fastest: the transpose of the [i, j, k] arrays.
    assert np.array_equal(got["pressure"], fluid.pressure().transpose(2, 1, 0).ravel())
    assert np.array_equal(got["porosity"], fluid.porosity().transpose(2, 1, 0).ravel())
    assert np.array_equal(got["velocity"].reshape(-1, 3), fluid.velocity().transpose(2, 1, 0, 3).reshape(-1, 3))
    assert got["TimeValue"][0] == fluid.time


def read_csv(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
    return header, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def test_recorder_and_solver_history_as_csv(tmp_path):
    s = linear_settings(hi=(0.1, 0.1, 0.2), gravity=(0, 0, -9.81), boundary=("periodic", "periodic", "wall"))
    s.walls[5] = sphere.WallControl(mode="velocity", velocity=0.01)
    sim = sphere.Simulation(s, [[0.05, 0.05, 0.05], [0.02, 0.05, 0.1]], 0.01, 2500)
    recorder = sphere.Recorder(sim, every=10)
    sim.run(100)
    recorder.write_csv(tmp_path / "diagnostics.csv")
    header, rows = read_csv(tmp_path / "diagnostics.csv")
    faces = [f"wall_{face}_{what}" for face in ("zlo", "zhi") for what in ("position_m", "velocity_m/s", "force_N")]
    assert header == ["time_s", "kinetic_J", "rotational_J", "potential_J", "elastic_J", "dissipated_visc_J",
                      "dissipated_fric_J", "boundary_work_J", "total_J", *faces]
    assert rows.shape == (11, len(header))
    assert np.array_equal(rows[:, 0], recorder.time)
    assert np.array_equal(rows[:, 1], recorder.energy["kinetic"])
    assert np.array_equal(rows[:, 8], recorder.energy["total"])
    assert np.array_equal(rows[:, 12], recorder.wall_position[:, 5])
    assert np.array_equal(rows[:, 13], recorder.wall_velocity[:, 5])
    assert np.all(rows[1:, 13] == pytest.approx(-0.01))  # the upper wall moves down at 1 cm/s
    assert np.array_equal(rows[:, 14], recorder.wall_force[:, 5])

    fluid = sphere.Fluid(lattice_bed("double"), (2, 2, 6), sphere.FluidSettings(top=sphere.FluidBoundary("pressure")))
    fluid.step(3)
    fluid.write_csv(tmp_path / "solver.csv")
    header, rows = read_csv(tmp_path / "solver.csv")
    history = fluid.solver_history
    assert header == ["time_s", "iterations", "residual", "converged"]
    assert np.array_equal(rows[:, 0], history.time) and np.array_equal(rows[:, 1], history.iterations)
    assert np.array_equal(rows[:, 2], history.residual) and np.all(rows[:, 3] == 1)


def test_any_columns_as_csv_and_the_errors(tmp_path):
    x = np.linspace(0, 1, 7) / 3
    sphere.write_csv(tmp_path / "any.csv", {"x_m": x, "count": np.arange(7)})
    header, rows = read_csv(tmp_path / "any.csv")
    assert header == ["x_m", "count"] and np.array_equal(rows[:, 0], x) and np.array_equal(rows[:, 1], np.arange(7))
    with pytest.raises(sphere.Error, match="the columns have different lengths: a 2, b 3"):
        sphere.write_csv(tmp_path / "bad.csv", {"a": [1, 2], "b": [1, 2, 3]})
    with pytest.raises(sphere.Error, match="column 0 name 'a,b' must be non-empty without commas"):
        sphere.write_csv(tmp_path / "bad.csv", {"a,b": [1]})
    with pytest.raises(sphere.Error, match="no columns"):
        sphere.write_csv(tmp_path / "bad.csv", {})
    assert not (tmp_path / "bad.csv").exists()
