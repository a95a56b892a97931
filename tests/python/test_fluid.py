"""The pore fluid from Python (sphere.Fluid): hydrostatic pressure (Navier-Stokes) and steady
Darcy flow through a fixed bed against their closed forms, the grid's fields as arrays, a
coupled run restarted from a checkpoint continuing bit for bit, the figures, and the errors."""

import math
import shutil
import subprocess

import numpy as np
import pytest

import sphere
from conftest import linear_settings

G = 9.81
SPACING, RADIUS = 0.005, 0.002


def lattice_bed(precision, layers=8, fixed=True, dt=1e-4):
    """A simple cubic lattice of 4 x 4 x `layers` spheres (spacing 5 mm, radius 2 mm, from the
    bottom) in a 20 x 20 x 60 mm box periodic in x and y: with 10 mm cells every cell of a layer
    holds the same solid."""
    x = (np.arange(4) + 0.5) * SPACING
    z = (np.arange(layers) + 0.5) * SPACING
    positions = np.array([[a, b, c] for c in z for b in x for a in x])
    s = linear_settings(hi=(0.02, 0.02, 0.06), k_n=1.0, boundary=("periodic", "periodic", "wall"), gravity=(0, 0, -G),
                        dt=dt)
    return sphere.Simulation(s, positions, RADIUS, 2600, fixed=np.full(len(positions), fixed), precision=precision)


def tolerance(precision):
    return 1e-11 if precision == "double" else 1e-5


def test_hydrostatic_pressure_around_a_fixed_bed(precision):
    sim = lattice_bed(precision)
    fluid = sphere.Fluid(sim, (2, 2, 6), sphere.FluidSettings(
        density=1000, viscosity=1e-3, top=sphere.FluidBoundary("pressure", pressure=250.0),
        tolerance=tolerance(precision), dem_steps=10))
    assert fluid.settings.gravity == pytest.approx((0, 0, -G))  # the simulation's
    assert fluid.cells == (2, 2, 6) and fluid.model == "navier_stokes"
    assert np.allclose(fluid.cell_width, (0.01, 0.01, 0.01))
    assert np.allclose(fluid.centres(), np.arange(6) * 0.01 + 0.005)
    # The particles' buoyancy -V grad p reaches the fluid a step late (explicit coupling): in a
    # layer of porosity phi the gradient approaches rho g by the factor 1 - phi (0.27) per step.
    fluid.step(30)
    assert fluid.time == pytest.approx(30 * 10 * sim.dt) and sim.steps == 300
    p = fluid.pressure()
    assert p.shape == (2, 2, 6)
    # p = p_top + rho g (z_top - z), z_top the top layer's centre: 250 Pa + 98.1 Pa per cm.
    expected = 250.0 + 1000 * G * (0.055 - fluid.centres())
    scale = 1e-9 if precision == "double" else 2e-5
    assert np.allclose(p, expected[None, None, :], rtol=0, atol=scale * expected.max())
    profile = sphere.Fluid.profile(p)
    assert profile.shape == (6,)
    assert np.allclose(profile, expected, rtol=0, atol=scale * expected.max())
    # (in float the grid's box and g are the float values)
    assert np.allclose(fluid.hydrostatic(), expected, rtol=1e-14 if precision == "double" else 1e-6, atol=0)
    # At rest: the velocity is the round-off of the projection.
    assert np.abs(fluid.velocity()).max() < (1e-12 if precision == "double" else 1e-6)
    # The bed: 2 x 2 x 2 spheres per cell in the four lower layers, none above.
    solid = 8 * 4 / 3 * math.pi * RADIUS**3 / 1e-6
    phi = fluid.porosity()
    assert np.allclose(phi[:, :, :4], 1 - solid, rtol=1e-5) and np.all(phi[:, :, 4:] == 1)
    assert np.allclose(fluid.particle_diameter()[:, :, :4], 2 * RADIUS, rtol=1e-5)
    assert np.all(fluid.particle_velocity() == 0)
    history = fluid.solver_history
    assert len(history.time) == 30 and history.converged.all()
    assert np.all(history.residual <= tolerance(precision))
    assert fluid.last_solve()["iterations"] == history.iterations[-1]
    assert fluid.stable_time_step() > fluid.dt


def test_steady_darcy_flow_through_a_fixed_bed(precision):
    # Inflow U at the bottom, p = 0 on the top layer, no gravity: in steady state q_z = U on every
    # face, and Darcy's law (D-2) over the face between layers k and k+1, with the harmonic mean
    # of their conductivities, gives p_k - p_k+1 = U h (1/K_k + 1/K_k+1) / 2.
    sim = lattice_bed(precision)
    sim_settings = sim.settings
    assert sim_settings.gravity == pytest.approx((0, 0, -G))
    U, d = 1e-4, 2 * RADIUS
    fluid = sphere.Fluid(sim, (2, 2, 6), sphere.FluidSettings(
        model="darcy", solver="cg", viscosity=1e-3, gravity=(0, 0, 0), permeability_prefactor=d * d / 180,
        bottom=sphere.FluidBoundary("inflow", velocity=U), top=sphere.FluidBoundary("pressure"),
        tolerance=tolerance(precision), dem_steps=10))
    fluid.step(20)
    K = fluid.conductivity()
    phi = fluid.porosity()
    assert np.allclose(K, d * d / 180 * np.minimum(phi, 0.9) ** 3 / (1 - np.minimum(phi, 0.9)) ** 2 / 1e-3,
                       rtol=1e-5)
    p = sphere.Fluid.profile(fluid.pressure())
    k_layers = sphere.Fluid.profile(K)
    h = fluid.cell_width[2]
    drop = U * h * (1 / k_layers[:-1] + 1 / k_layers[1:]) / 2
    rtol = 1e-7 if precision == "double" else 2e-3
    assert np.allclose(p[:-1] - p[1:], drop, rtol=rtol)
    assert p[-1] == 0
    q = fluid.darcy_flux()
    # Inner layers: the mean of the two face fluxes, U; every column alike.
    assert np.allclose(q[:, :, 1:-1, 2], U, rtol=rtol) and np.allclose(q[:, :, :, :2], 0, atol=rtol * U)
    with pytest.raises(sphere.Error, match="fluid.velocity: the navier_stokes model's field; this fluid is darcy"):
        fluid.velocity()
    assert np.array_equal(fluid.flow(), q)
    assert fluid.stable_time_step() == math.inf


@pytest.mark.parametrize("model", ["navier_stokes", "darcy"])
def test_a_coupled_run_continues_from_its_checkpoint_bit_for_bit(precision, model, tmp_path):
    def coupled():
        sim = lattice_bed(precision, layers=3, fixed=False, dt=0.0)
        settings = sphere.FluidSettings(model=model, viscosity=1e-3, top=sphere.FluidBoundary("pressure"),
                                        permeability_prefactor=(2 * RADIUS) ** 2 / 180,
                                        tolerance=tolerance(precision), dem_steps=10)
        return sim, settings

    sim, settings = coupled()
    fluid = sphere.Fluid(sim, (2, 2, 6), settings)
    fluid.step(3)
    path = tmp_path / "coupled.ck"
    fluid.write_checkpoint(path)
    fluid.step(3)

    again = sphere.read_checkpoint(path)
    assert again.precision == precision
    restored = sphere.Fluid(again, (2, 2, 6), settings)
    restored.restore(path)
    assert restored.time == pytest.approx(fluid.time - 3 * fluid.dt)
    restored.step(3)
    assert again.steps == sim.steps and again.time == sim.time
    a, b = sim.snapshot(), again.snapshot()
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.velocities, b.velocities)
    assert np.array_equal(fluid.pressure(), restored.pressure())
    assert np.array_equal(fluid.flow(), restored.flow())
    assert fluid.work_on_particles() == restored.work_on_particles()
    # The particles fell through the fluid: the drag did work against them.
    assert a.positions[:, 2].max() < 2.5 * SPACING and fluid.work_on_particles() < 0

    # A checkpoint without a fluid section, and a fluid of another grid.
    plain = tmp_path / "plain.ck"
    sim.write_checkpoint(plain)
    with pytest.raises(sphere.Error, match="no fluid section"):
        sphere.Fluid(again, (2, 2, 6), settings).restore(plain)
    with pytest.raises(sphere.Error, match="grid has 2 x 2 x 6 cells, this one 2 x 2 x 5"):
        sphere.Fluid(again, (2, 2, 5), settings).restore(path)
    # From the checkpoint alone (its stored setup): the fluid restore() gives; on a simulation
    # of another box, refused.
    fresh = sphere.Fluid(sphere.read_checkpoint(path), (2, 2, 6), settings)
    fresh.restore(path)
    built = sphere.Fluid.from_checkpoint(sphere.read_checkpoint(path), path)
    assert (built.model, built.settings.solver, built.cells, built.dem_steps) == (fresh.model, fresh.settings.solver,
                                                                                  fresh.cells, fresh.dem_steps)
    assert built.time == fresh.time and np.array_equal(built.pressure(), fresh.pressure())
    taller = sphere.Simulation(linear_settings(hi=(0.02, 0.02, 0.08), k_n=1.0, boundary=("periodic", "periodic", "wall")),
                               [[0.01, 0.01, 0.01]], RADIUS, 2600, precision=precision)
    with pytest.raises(sphere.Error, match=r"grid spans \[0, 0.0(6|59+\d*)\] m along z, this one \[0, 0.0(8|79+\d*|80+\d*)\] m"):
        sphere.Fluid.from_checkpoint(taller, path)


def test_figures_show_the_profiles_and_the_solves(tmp_path):
    plot = pytest.importorskip("sphere.plot")
    sim = lattice_bed("double")
    fluid = sphere.Fluid(sim, (2, 2, 6), sphere.FluidSettings(density=1000, top=sphere.FluidBoundary("pressure")))
    fluid.step(3)
    fig = plot.fluid_pressure(fluid, tmp_path / "pressure.png")
    assert (tmp_path / "pressure.png").stat().st_size > 0
    mean = fig.axes[0].lines[0]
    assert np.array_equal(mean.get_xdata(), sphere.Fluid.profile(fluid.pressure()))
    assert np.array_equal(mean.get_ydata(), fluid.centres())
    assert np.array_equal(fig.axes[0].lines[1].get_xdata(), fluid.hydrostatic())
    fig = plot.fluid_velocity(fluid, tmp_path / "velocity.png")
    assert (tmp_path / "velocity.png").stat().st_size > 0
    assert np.array_equal(fig.axes[0].lines[4].get_xdata(), sphere.Fluid.profile(fluid.velocity())[:, 2])
    assert np.array_equal(fig.axes[1].lines[0].get_xdata(), sphere.Fluid.profile(fluid.porosity()))
    fig = plot.solver_convergence(fluid, tmp_path / "convergence.png")
    assert (tmp_path / "convergence.png").stat().st_size > 0
    assert np.array_equal(fig.axes[0].lines[0].get_ydata(), fluid.solver_history.iterations)
    assert len(fig.axes[0].lines[0].get_xdata()) == 3
    with pytest.raises(sphere.Error, match="plot.fluid_pressure: Simulation given; a sphere.Fluid is needed"):
        plot.fluid_pressure(sim)


@pytest.mark.parametrize("change, message", [
    (dict(model="lattice_boltzmann"), "fluid.model = 'lattice_boltzmann': not one of 'navier_stokes', 'darcy'"),
    (dict(solver="jacobi"), "fluid.solver = 'jacobi': not one of 'mg', 'cg'"),
    (dict(viscosity=-1.0), "fluid: viscosity = -1 Pa s must be positive and finite"),
    (dict(bottom=sphere.FluidBoundary("inflow", velocity=1e-3)), "an inflow bottom .* needs a prescribed pressure"),
    (dict(top=sphere.FluidBoundary("drain")), "fluid.top.kind = 'drain': not one of 'no_flow', 'pressure', 'inflow'"),
    (dict(dem_steps=0), "fluid.dem_steps = 0: a whole number from 1 to 4294967295 is needed"),
    (dict(max_iterations=2.5), "fluid.max_iterations = 2.5: a whole number from 1"),
    (dict(criterion="exact"), "fluid.criterion = 'exact'"),
    (dict(porosity="voronoi"), "fluid.porosity = 'voronoi'"),
    (dict(model="darcy"), "darcy: permeability_prefactor = 0 m\\^2 must be positive"),
])
def test_bad_fluid_settings_are_named(change, message):
    sim = lattice_bed("double")
    with pytest.raises(sphere.Error, match=message):
        sphere.Fluid(sim, (2, 2, 6), sphere.FluidSettings(**change))


def test_bad_grids_and_fields_of_the_other_model_are_named():
    sim = lattice_bed("double")
    with pytest.raises(sphere.Error, match="fluid: cells = 8: three whole numbers"):
        sphere.Fluid(sim, 8, None)
    with pytest.raises(sphere.Error, match="fluid: cells\\[2\\] = 2.5 is not a whole number"):
        sphere.Fluid(sim, (2, 2, 2.5))
    with pytest.raises(sphere.Error, match="fluid_grid|cells"):
        sphere.Fluid(sim, (2, 0, 6))
    fluid = sphere.Fluid(sim, (2, 2, 6))
    for field in ("darcy_flux", "conductivity"):
        with pytest.raises(sphere.Error, match=f"fluid.{field}: the darcy model's field; this fluid is navier_stokes"):
            getattr(fluid, field)()
    with pytest.raises(TypeError, match="a sphere.Simulation is needed"):
        sphere.Fluid("sim", (2, 2, 6))


@pytest.mark.parametrize("model, solver", [("navier_stokes", "mg"), ("darcy", "cg")])
def test_the_program_runs_a_coupled_checkpoint_as_the_process_does(model, solver, tmp_path):
    # A coupled run written from Python, run by the sphere program to 5 more fluid steps, equals
    # the same steps taken in-process (the final checkpoint, byte for byte); read back with
    # Fluid.from_checkpoint; and resumed from an earlier output, the same files.
    from conftest import cpp_program

    program = cpp_program("SPHERE_PROGRAM", "the sphere program")
    sim = lattice_bed("double", layers=3, fixed=False, dt=0.0)
    # (Navier-Stokes has no permeability: its setup stores the Darcy fields' defaults)
    settings = sphere.FluidSettings(model=model, solver=solver, viscosity=1e-3, top=sphere.FluidBoundary("pressure"),
                                    permeability_prefactor=(2 * RADIUS) ** 2 / 180 if model == "darcy" else 0.0,
                                    dem_steps=10)
    fluid = sphere.Fluid(sim, (2, 2, 6), settings)
    fluid.step(2)
    fluid.write_checkpoint(tmp_path / "coupled.ck")
    start = sim.steps
    fluid.step(5)
    fluid.write_checkpoint(tmp_path / "in-process.ck")

    total = (start + 50) * sim.dt
    dry = subprocess.run([program, str(tmp_path / "coupled.ck"), "--dry", "-t", repr(total)], capture_output=True,
                         text=True, check=True).stdout
    assert f"fluid          {model} ({solver} pressure solver, gidaspow drag), 2 x 2 x 6 cells" in dry
    assert "fluid step     10 DEM steps" in dry
    assert "fluid bottom   no_flow" in dry
    assert f"fluid solver   tolerance {settings.tolerance:g} (relative_residual), at most {settings.max_iterations}" in dry
    assert "coupling       porosity cell_volume, pressure force on" in dry
    done = sphere.run_program(tmp_path / "coupled.ck", total, interval=2 * fluid.dt, out=tmp_path / "out",
                              program=program)
    outputs = sorted((tmp_path / "out").glob("coupled.output*.ck"))
    assert len(outputs) == 4  # the input's state, after 2, 4 and 5 fluid steps
    assert outputs[-1].read_bytes() == (tmp_path / "in-process.ck").read_bytes()
    assert sorted(p.name for p in (tmp_path / "out").glob("coupled.output*.vti")) == [p.stem + ".vti" for p in outputs]
    assert (tmp_path / "out" / "coupled.fluid.pvd").read_text().count("<DataSet") == 4

    again = sphere.read_checkpoint(outputs[-1])
    read = sphere.Fluid.from_checkpoint(again, outputs[-1])
    assert read.settings == fluid.settings and read.cells == fluid.cells and read.model == model
    assert np.array_equal(read.pressure(), fluid.pressure()) and np.array_equal(read.flow(), fluid.flow())

    # A run that stopped after output 1: the status file says so, the later files are gone.
    resumed = tmp_path / "resumed"
    shutil.copytree(tmp_path / "out", resumed)
    status = (resumed / "coupled.status.dat").read_text().split("\n")
    first = status[0].split()
    status[0] = " ".join([first[0], first[1], "1"])
    (resumed / "coupled.status.dat").write_text("\n".join(status))
    for later in ("00002", "00003"):
        for extension in (".ck", ".vtu", ".vti"):
            (resumed / f"coupled.output{later}{extension}").unlink()
    said = subprocess.run([program, str(tmp_path / "coupled.ck"), "-t", repr(total), "-i", repr(2 * fluid.dt),
                           "-o", str(resumed)], capture_output=True, text=True, check=True).stdout
    assert "resuming from output 1 " in said
    for f in sorted((tmp_path / "out").iterdir()):
        if f.name != "coupled.status.dat":
            assert (resumed / f.name).read_bytes() == f.read_bytes(), f.name


def test_the_program_refuses_a_coupled_run_in_mixed_precision(tmp_path):
    from conftest import cpp_program

    program = cpp_program("SPHERE_PROGRAM", "the sphere program")
    sim = lattice_bed("double")
    fluid = sphere.Fluid(sim, (2, 2, 6), sphere.FluidSettings(top=sphere.FluidBoundary("pressure")))
    fluid.step()
    fluid.write_checkpoint(tmp_path / "coupled.ck")
    with pytest.raises(sphere.Error, match="holds a pore-fluid section \\(model navier_stokes\\): precision mixed is "
                                           "not coupled to the pore fluid; use float or double"):
        sphere.run_program(tmp_path / "coupled.ck", 1.0, out=tmp_path / "out", precision="mixed", program=program)
    assert not (tmp_path / "out").exists()
