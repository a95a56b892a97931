"""The C++ uniaxial example (examples/uniaxial/main.cpp) as a call (sphere's uniaxialStrainRate):
a sample poured under gravity into a box periodic in x and y (or a saved one), compressed by the
upper wall moving down at a prescribed velocity; the sample cannot widen, so this is uniaxial
strain. The same options give the example's printed numbers, final checkpoint and series.csv
columns to the last bit (same precision, same thread count): every value is computed in the same
order and at the same steps as there.
"""

from dataclasses import dataclass, field

import numpy as np

from ._sphere import Error
from .granular import TOP, prepared_sample, sample_contact, velocity_wall
from .simulation import Simulation, _steps_for

FLOOR = 4  # the lower wall's face (z-)


@dataclass
class UniaxialSeries:
    """The compression sampled every output interval from its start (the example's series.csv,
    its last columns): time (s), axial strain (the upper wall's descent over the initial sample
    height), axial stress (Pa, the particles' normal stress on the upper wall), porosity and void
    ratio. NumPy arrays, one value per row."""

    time: np.ndarray
    axial_strain: np.ndarray
    axial_stress: np.ndarray
    porosity: np.ndarray
    void_ratio: np.ndarray


@dataclass
class Uniaxial:
    """What uniaxial() found: the simulation at the end; the initial sample height (m, upper
    wall to floor) and the upper wall's initial position (m); at the end the axial strain, the
    axial and floor stresses (Pa), the porosity and void ratio; and the series (UniaxialSeries)."""

    simulation: Simulation
    height: float
    top: float
    axial_strain: float
    axial_stress: float
    floor_stress: float
    porosity: float
    void_ratio: float
    series: UniaxialSeries = field(repr=False)


def uniaxial(particles=800, radius=0.01, spread=0.1, density=2500.0, k_n=1e5, friction=0.5, restitution=0.5, seed=1,
             wall_mass=0.1, velocity=0.05, duration=0.4, output_interval=0.02, precision="double", checkpoint=None,
             verbose=True, sample=None):
    """The uniaxial example: a sample (deposited_sample, periodic in x and y, or with `sample` the
    saved sample at that path, as the example's --sample), then the upper wall moved down at
    `velocity` (m/s) for `duration` (s). The compression must stay below half the sample's height
    (sphere.Error otherwise). Prints the example's lines when `verbose`, writes the final
    checkpoint to `checkpoint` when given, and returns a Uniaxial, whose series has a row every
    `output_interval` (s). The options are the example's (uniaxial --help), with the same
    defaults; `wall_mass` is accepted as the example's --wall-mass is, and unused (no wall is
    stress-controlled)."""
    contact = sample_contact(radius, density, k_n, friction, restitution)
    sim = prepared_sample(sample, contact, verbose, particles=particles, radius=radius, spread=spread,
                          density=density, k_n=k_n, friction=friction, restitution=restitution, seed=seed,
                          precision=precision)
    walls = sim.walls().position
    z0, floor = walls[TOP], walls[FLOOR]
    height0 = z0 - floor
    if verbose:
        print("uniaxial: %d particles (%s), sample at t = %.3f s; sample height %.6f m, porosity %.4f"
              % (sim.size, precision, sim.time, height0, sim.porosity()["porosity"]))
    strain_end = velocity * duration / height0
    if not strain_end < 0.5:
        raise Error("sphere: velocity=%g m/s for duration=%g s would compress the sample by %g%% of its height; "
                    "at most 50%% is allowed" % (velocity, duration, 100 * strain_end))
    sim.set_wall_control(TOP, velocity_wall(velocity))

    def strain(s):
        return (z0 - s.walls().position[TOP]) / height0

    rows = []

    def row(s):
        p = s.porosity()
        rows.append((s.time, strain(s), s.wall_normal_stress(TOP), p["porosity"], p["void_ratio"]))

    # The example's rows: one now, then one at every multiple of the interval's steps.
    row(sim)
    first = sim.steps
    sim.add_observer(max(_steps_for(output_interval, sim.dt), 1), lambda s: s.steps != first and row(s))
    sim.run(_steps_for(duration, sim.dt))

    p = sim.porosity()
    series = UniaxialSeries(*np.array(rows, dtype=np.float64).reshape(-1, 5).T)
    result = Uniaxial(sim, height0, z0, strain(sim), sim.wall_normal_stress(TOP), sim.wall_normal_stress(FLOOR),
                      p["porosity"], p["void_ratio"], series)
    if verbose:
        print("%-34s %14.6f" % ("axial strain", result.axial_strain))
        print("%-34s %14.1f" % ("axial stress (Pa)", result.axial_stress))
        print("%-34s %14.1f" % ("floor stress (Pa)", result.floor_stress))
        print("%-34s %14.6f" % ("porosity", result.porosity))
        print("%-34s %14.6f" % ("void ratio", result.void_ratio))
    if checkpoint is not None:
        sim.write_checkpoint(checkpoint)
    return result
