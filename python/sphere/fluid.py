"""The pore fluid coupled to a Simulation (``sphere::fluid_coupling`` on the host backend,
docs/fluid.md): a fluid grid over the simulation's world box, advanced in coupled steps of
dem_steps DEM steps, its cell fields as NumPy arrays, their horizontal profiles, the pressure
solver's convergence per step, and checkpoints of both (docs/python.md, *Pore fluid*)."""

import dataclasses
import os
from dataclasses import dataclass

import numpy as np

from .record import write_csv
from ._sphere import Error
from .settings import FluidBoundary, FluidSettings
from .simulation import Simulation, _steps_for, backend


@dataclass
class SolverHistory:
    """The pressure solve of every coupled step a Fluid took: `time` (s, at the step's end),
    `iterations`, `residual` (the criterion's value) and `converged` (bool), arrays of one entry
    per step."""

    time: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray
    converged: np.ndarray


class Fluid:
    """The pore fluid coupled to the particles of `simulation` (a sphere.Simulation).

    Fluid(simulation, cells, settings=None): a grid of cells = (nx, ny, nz) cells over the
    simulation's world box (x and y are periodic for the fluid whatever the box's boundaries;
    docs/fluid.md), with a sphere.FluidSettings (None: its defaults, Navier-Stokes water), in the
    simulation's precision. The library checks everything and raises sphere.Error naming the
    first bad value. A coupled step (step, run_for) advances the fluid by dem_steps DEM steps
    and then the simulation by as many, with the fluid forces held; running the simulation on
    its own keeps the last forces.
    """

    def __init__(self, simulation, cells, settings=None):
        if not isinstance(simulation, Simulation):
            raise TypeError(f"sphere.Fluid: simulation is a {type(simulation).__name__}; a sphere.Simulation is needed")
        settings = FluidSettings() if settings is None else dataclasses.replace(settings)
        if settings.gravity is None:
            settings.gravity = simulation.settings.gravity
        self._impl = backend(simulation.precision).Fluid(simulation._impl, cells, settings)
        self._sim = simulation
        self._settings = settings
        self._history = []

    @classmethod
    def from_checkpoint(cls, simulation, path):
        """The Fluid a checkpoint of a coupled run describes (its cells and FluidSettings, which
        Fluid.write_checkpoint and the sphere program store beside the fluid's state), built on
        `simulation` (read from the same file with sphere.read_checkpoint) and restored from
        it: the sphere program's outputs of a coupled run read back. Raises sphere.Error for a
        file without a fluid section or setup, or a drag law other than Gidaspow's."""
        if not isinstance(simulation, Simulation):
            raise TypeError(f"sphere.Fluid: simulation is a {type(simulation).__name__}; a sphere.Simulation is needed")
        impl, d = backend(simulation.precision).fluid_from_checkpoint(simulation._impl, os.fspath(path))

        def end(name):
            return FluidBoundary(d[name + "_kind"], *(d[f"{name}_{field}"] for field in
                                                      ("pressure", "amplitude", "frequency", "phase", "velocity")))

        settings = FluidSettings(
            model=d["model"], solver=d["solver"], density=d["density"], viscosity=d["viscosity"], beta=d["beta"],
            gravity=(d["gravity_x"], d["gravity_y"], d["gravity_z"]), bottom=end("bottom"), top=end("top"),
            tolerance=d["tolerance"], max_iterations=d["max_iterations"], criterion=d["criterion"],
            compressibility=d["compressibility"], permeability_prefactor=d["permeability_prefactor"],
            max_porosity=d["max_porosity"], dem_steps=d["dem_steps"], pressure_force=d["pressure_force"],
            porosity=d["porosity_method"])
        fluid = cls.__new__(cls)
        fluid._impl, fluid._sim, fluid._settings, fluid._history = impl, simulation, settings, []
        return fluid

    def __repr__(self):
        nx, ny, nz = self.cells
        return f"<sphere.Fluid: {self.model}, {nx} x {ny} x {nz} cells, t = {self.time:g} s>"

    @property
    def simulation(self):
        """The coupled sphere.Simulation."""
        return self._sim

    @property
    def settings(self):
        """A copy of the FluidSettings (gravity as used)."""
        return dataclasses.replace(self._settings)

    @property
    def model(self):
        """'navier_stokes' or 'darcy'."""
        return self._impl.model

    @property
    def cells(self):
        """(nx, ny, nz)."""
        return self._impl.cells

    @property
    def cell_width(self):
        """The cells' widths (m) along x, y, z."""
        return self._impl.cell_width

    @property
    def lo(self):
        """The grid's lower corner (m): the world box's."""
        return self._impl.lo

    @property
    def hi(self):
        """The grid's upper corner (m)."""
        return self._impl.hi

    @property
    def dem_steps(self):
        """DEM steps per coupled step."""
        return self._impl.dem_steps

    @property
    def dt(self):
        """The fluid time step (s): dem_steps times the simulation's."""
        return self.dem_steps * self._sim.dt

    @property
    def time(self):
        """The fluid's time (s)."""
        return self._impl.time

    def centres(self, axis=2):
        """The cell centres (m) along an axis (0, 1, 2 for x, y, z)."""
        n, lo, width = self.cells[axis], self.lo[axis], self.cell_width[axis]
        return lo + (np.arange(n) + 0.5) * width

    def step(self, steps=1):
        """Takes `steps` coupled steps. Raises sphere.Error, before the step that breaks it
        advances anything, when the fluid step exceeds a stability limit of the fluid or a
        particle's response time to the drag, or when the pressure solve does not converge."""
        sim = self._sim
        sim._refuse_in_observer("Fluid.step")
        for _ in range(steps):
            self._impl.step(sim._impl)
            solve = self._impl.last_solve()
            self._history.append((self.time, solve["iterations"], solve["residual"], solve["converged"]))

    def run_for(self, seconds):
        """Takes the coupled steps in `seconds` of simulated time (rounded to the nearest whole
        number of fluid steps); returns that number."""
        steps = _steps_for(seconds, self.dt)
        self.step(steps)
        return steps

    @property
    def solver_history(self):
        """The pressure solves of the steps this object took: a SolverHistory."""
        columns = list(zip(*self._history)) if self._history else [(), (), (), ()]
        return SolverHistory(np.array(columns[0], dtype=float), np.array(columns[1], dtype=np.int64),
                             np.array(columns[2], dtype=float), np.array(columns[3], dtype=bool))

    def last_solve(self):
        """The last pressure solve: a dict of iterations, residual and converged."""
        return self._impl.last_solve()

    def work_on_particles(self):
        """Work the fluid forces did on the free particles so far (J)."""
        return self._impl.work_on_particles()

    def stable_time_step(self):
        """The largest stable fluid time step (s) now: Navier-Stokes' diffusive and advective
        limits (infinity for Darcy, which is implicit)."""
        return self._impl.stable_time_step()

    # Cell fields: arrays indexed [i, j, k] (x, y, z), copies.
    def pressure(self):
        """The pressure (Pa) at the cell centres, (nx, ny, nz)."""
        return self._impl.pressure()

    def porosity(self):
        """The porosity of each cell (the estimator's, as the fluid last used it), (nx, ny, nz)."""
        return self._impl.porosity()

    def porosity_rate(self):
        """Its rate of change (1/s), (nx, ny, nz)."""
        return self._impl.porosity_rate()

    def particle_velocity(self):
        """The volume-weighted mean particle velocity of each cell (m/s; 0 where none),
        (nx, ny, nz, 3)."""
        return self._impl.particle_velocity()

    def particle_diameter(self):
        """The volume-weighted mean particle diameter of each cell (m; 0 where none), (nx, ny, nz)."""
        return self._impl.particle_diameter()

    def velocity(self):
        """Navier-Stokes: the fluid velocity at the cell centres (m/s; the mean of the two faces
        per axis), (nx, ny, nz, 3). sphere.Error for the Darcy model (darcy_flux)."""
        return self._impl.velocity()

    def darcy_flux(self):
        """Darcy: the flux q = -k/mu (grad p - rho g) at the cell centres (m/s: the superficial
        velocity of the fluid relative to the solid), (nx, ny, nz, 3). sphere.Error for
        Navier-Stokes (velocity)."""
        return self._impl.darcy_flux()

    def conductivity(self):
        """Darcy: the hydraulic conductivity k / mu of each cell (m^2 / (Pa s)), (nx, ny, nz)."""
        return self._impl.conductivity()

    def flow(self):
        """The model's velocity field: velocity() for Navier-Stokes, darcy_flux() for Darcy."""
        return self.velocity() if self.model == "navier_stokes" else self.darcy_flux()

    @staticmethod
    def profile(field):
        """The mean over x and y of each z layer of a cell field: (nz,) of an (nx, ny, nz) field,
        (nz, 3) of an (nx, ny, nz, 3) one."""
        return np.asarray(field).mean(axis=(0, 1))

    def hydrostatic(self):
        """The hydrostatic pressure (Pa) at the layers' centres, (nz,), when the top holds a
        prescribed pressure: p_top + rho_f g_z (z - z_top), z_top the top layer's centre (the
        modulation of p_top at the fluid's time included); None otherwise."""
        top = self._settings.top
        if top.kind != "pressure":
            return None
        z = self.centres()
        p_top = top.pressure + top.amplitude * np.sin(2 * np.pi * top.frequency * self.time + top.phase)
        return p_top + self._settings.density * self._settings.gravity[2] * (z - z[-1])

    def write_vtk(self, path):
        """Writes the fluid's cells to the VTK image `path` (.vti, atomically; docs/io.md): the
        pressure, velocity, porosity and the model's other cell fields at the fluid's time, as
        fluid_consolidation's frames."""
        self._impl.write_vtk(os.fspath(path))

    def write_csv(self, path):
        """Writes solver_history to the CSV file `path` (atomically): time_s, iterations,
        residual, converged (1 or 0), one row per coupled step."""
        h = self.solver_history
        write_csv(path, {"time_s": h.time, "iterations": h.iterations, "residual": h.residual,
                         "converged": h.converged})

    def write_checkpoint(self, path):
        """Writes the simulation and the fluid's state to `path` (atomically): read_checkpoint
        gives the simulation back, and restore the fluid."""
        self._impl.write_checkpoint(os.fspath(path), self._sim._impl)

    def restore(self, path):
        """Continues the fluid from the checkpoint at `path` (written by write_checkpoint of a
        Fluid with the same cells and settings; the grid and the model are checked) next to
        its simulation read with sphere.read_checkpoint(path): the coupled steps then give the
        bits of the run that wrote it (same precision and thread count). Raises sphere.Error for
        a file without a fluid section or one of another grid or model."""
        self._impl.restore(os.fspath(path))
