"""The C++ shear example (examples/shear/main.cpp) as a call (sphere's shear()): a sample
poured under gravity into a box periodic in x and y (or a saved one), consolidated under the
upper wall at a normal stress, then turned into a shear cell: the bottom layer fixed, the top
layer driven along x at the strain rate times the height between the layers while free to rise,
the upper wall holding the stress. Walls are frictionless. The same options give the example's
printed numbers and final checkpoint to the last bit (same precision, same thread count): every
value is computed in the same order and at the same steps as there.
"""

from dataclasses import dataclass, field

import numpy as np

from .granular import TOP, prepared_sample, sample_contact, stress_wall
from .simulation import Simulation, _steps_for, backend


@dataclass
class ShearSeries:
    """The shear phase sampled every output interval, as the example's series.csv (its last
    columns): time (s), shear strain, mean shear stress tau and wall normal stress sigma over
    the interval (Pa, sampled every 10 steps), their ratio tau/sigma (the effective friction
    coefficient), dilation of the sample (m: the upper wall's rise since the shear began),
    porosity and void ratio. NumPy arrays, one value per row."""

    time: np.ndarray
    strain: np.ndarray
    shear_stress: np.ndarray
    normal_stress: np.ndarray
    friction: np.ndarray
    dilation: np.ndarray
    porosity: np.ndarray
    void_ratio: np.ndarray


@dataclass
class Shear:
    """What shear() found: the simulation at the end; the height between the layers' centres
    when the shear began (m), the top layer's velocity (m/s) and the layers (`fixed` and
    `driven` user indices); at the end the shear strain, the dilation (m), the porosity, the
    work done on the driven layer (J) and the frictional and viscous dissipation of the whole
    run (J); and the series of the shear phase (ShearSeries)."""

    simulation: Simulation
    height: float
    velocity: float
    fixed: np.ndarray
    driven: np.ndarray
    strain: float
    dilation: float
    porosity: float
    drive_work: float
    frictional_dissipation: float
    viscous_dissipation: float
    series: ShearSeries = field(repr=False)


class _Recorder:
    """The example's output rows during the shear (every output interval): the tracker's update
    and the stress averages, reset at each row."""

    def __init__(self):
        self.shearing = False
        self.tracker = None
        self.z_start = 0.0
        self.tau = self.sigma = 0.0
        self.samples = 0
        self.rows = []

    def mean_tau(self):
        return self.tau / self.samples if self.samples else 0.0

    def mean_sigma(self):
        return self.sigma / self.samples if self.samples else 0.0

    def row(self, sim):
        if not self.shearing:
            return
        self.tracker.update(sim._impl)
        tau, sigma = self.mean_tau(), self.mean_sigma()
        p = sim.porosity()
        self.rows.append((sim.time, self.tracker.strain, tau, sigma, tau / sigma if sigma > 0 else 0.0,
                          sim.walls().position[TOP] - self.z_start, p["porosity"], p["void_ratio"]))
        self.tau = self.sigma = 0.0
        self.samples = 0

    def series(self):
        columns = np.array(self.rows, dtype=np.float64).reshape(-1, 8).T
        return ShearSeries(*columns)


def shear(particles=800, radius=0.01, spread=0.1, density=2500.0, k_n=1e5, friction=0.5, restitution=0.5, seed=1,
          wall_mass=0.1, stress=1e4, consolidation_time=0.3, strain_rate=0.25, strain=0.3, output_interval=0.02,
          precision="double", checkpoint=None, verbose=True, sample=None):
    """The shear example: a sample (deposited_sample, or with `sample` the saved sample at that
    path, as the example's --sample), its upper wall held at the normal stress `stress` (Pa,
    mass `wall_mass` times the particles') for `consolidation_time` s, then sheared at
    `strain_rate` (1/s) to the shear strain `strain`: particles whose bottom lies within one
    largest diameter of the sample's bottom are fixed, those whose top lies within one of its
    top move along x at strain_rate times the height between the two layers' centres (the
    largest diameter is the options' nominal 2 radius (1 + spread) for a deposited sample, the
    largest in the file for a saved one). Particle-wall contacts are frictionless. Prints the
    example's lines when `verbose`, writes the final checkpoint to `checkpoint` when given, and
    returns a Shear. `output_interval` (s) is the example's: the strain tracker and the stress
    averages are sampled at its rows (and so are the result's series). The options are the
    example's (shear --help), with the same defaults."""
    wall = sample_contact(radius, density, k_n, friction, restitution)
    wall.mu_s = wall.mu_d = 0.0
    sim = prepared_sample(sample, wall, verbose, particles=particles, radius=radius, spread=spread, density=density,
                          k_n=k_n, friction=friction, restitution=restitution, seed=seed, precision=precision)
    impl, ext = sim._impl, backend(precision)
    if verbose:
        print("shear: %d particles (%s), sample at t = %.3f s; porosity %.4f"
              % (sim.size, precision, sim.time, sim.porosity()["porosity"]))
    sim.set_wall_control(TOP, stress_wall(sim, stress, wall_mass))
    area = ext.wall_area(impl, TOP)

    # The example's output rows every output interval, from before the consolidation on.
    recorder = _Recorder()
    every = max(_steps_for(output_interval, sim.dt), 1)
    sim.add_observer(every, recorder.row)
    sim.run(_steps_for(consolidation_time, sim.dt))

    # The shear cell, each layer one largest diameter thick.
    if sample is None:
        thickness = 2 * radius * (1 + spread)
    else:
        thickness = 2 * float(np.max(sim.snapshot().radii))
    height = ext.shear_cell_height(impl, thickness)
    velocity = strain_rate * height
    layers = ext.make_shear_cell(impl, thickness, velocity, 0.0)
    recorder.tracker = ext.ShearTracker(impl, 0)
    recorder.z_start = sim.walls().position[TOP]
    recorder.shearing = True
    if verbose:
        print("consolidated: %.6f m between the layers, porosity %.4f; shearing at %.4g m/s (%d fixed, %d driven "
              "particles)" % (height, sim.porosity()["porosity"], velocity, len(layers["bottom"]), len(layers["top"])))

    def sample_stresses(s):
        recorder.tau += ext.shear_stress(s._impl, layers, area, 0)
        recorder.sigma += s.wall_normal_stress(TOP)
        recorder.samples += 1

    sim.add_observer(10, sample_stresses)
    sim.run(_steps_for(strain / strain_rate, sim.dt))

    recorder.tracker.update(impl)
    e = sim.energy()
    result = Shear(sim, height, velocity, np.array(layers["bottom"], dtype=np.int64),
                   np.array(layers["top"], dtype=np.int64), recorder.tracker.strain,
                   sim.walls().position[TOP] - recorder.z_start, sim.porosity()["porosity"], ext.drive_work(impl),
                   e.dissipated_friction, e.dissipated_viscous, recorder.series())
    if verbose:
        print("%-34s %14.6f" % ("shear strain", result.strain))
        print("%-34s %14.6e" % ("dilation (m)", result.dilation))
        print("%-34s %14.6f" % ("porosity", result.porosity))
        print("%-34s %14.6e" % ("work of the driven layer (J)", result.drive_work))
        print("%-34s %14.6e" % ("frictional dissipation (J)", result.frictional_dissipation))
        print("%-34s %14.6e" % ("viscous dissipation (J)", result.viscous_dissipation))
        print("(tau/sigma against strain: the friction_coefficient column of series.csv; plot with "
              "scripts/plot_series.py)")
    if checkpoint is not None:
        sim.write_checkpoint(checkpoint)
    return result
