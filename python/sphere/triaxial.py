"""The C++ triaxial example (examples/triaxial/main.cpp) as a call (sphere's triaxial): a sample
poured under gravity into a box closed by walls on every side (or a saved one), its four side
walls and the upper wall held at a confining stress (the isotropic phase), then the upper wall
moved down at a prescribed velocity while the side walls keep the confining stress (the axial
compression). The same options give the example's printed numbers, final checkpoint and
series.csv columns to the last bit (same precision, same thread count): every value is computed
in the same order and at the same steps as there.
"""

from dataclasses import dataclass, field

import numpy as np

from .granular import TOP, frictional_wall_contact, prepared_sample, stress_wall, velocity_wall
from .simulation import Simulation, _steps_for

SIDES = (0, 1, 2, 3)  # the side walls' faces: x-, x+, y-, y+


def box_volume(sim):
    """The volume between the six walls (m^3)."""
    w = sim.walls().position
    return (w[1] - w[0]) * (w[3] - w[2]) * (w[5] - w[4])


def side_stress(sim):
    """The mean normal stress of the particles on the four side walls (Pa)."""
    total = 0.0
    for f in SIDES:  # in order, as the example sums
        total += sim.wall_normal_stress(f)
    return total / 4


@dataclass
class TriaxialSeries:
    """Both phases sampled every output interval (the example's series.csv rows, its last
    columns), with the stress path: time (s); `axial` (True in the rows of the axial
    compression, False in those of the isotropic phase); axial and volumetric strain (measured
    from the end of the isotropic phase, compression positive; NaN in the isotropic phase, where
    the example's CSV holds them against unset references); axial stress sigma_1 (Pa, upper
    wall), lateral stress sigma_3 (Pa, mean of the side walls); deviatoric stress q = sigma_1 -
    sigma_3 and mean stress p = (sigma_1 + 2 sigma_3) / 3 (Pa); porosity and void ratio. NumPy
    arrays, one value per row."""

    time: np.ndarray
    axial: np.ndarray
    axial_strain: np.ndarray
    volumetric_strain: np.ndarray
    axial_stress: np.ndarray
    lateral_stress: np.ndarray
    deviatoric_stress: np.ndarray
    mean_stress: np.ndarray
    porosity: np.ndarray
    void_ratio: np.ndarray


@dataclass
class Triaxial:
    """What triaxial() found: the simulation at the end; at the end of the isotropic phase the
    upper wall's position (m), the sample's height (m) and the box volume (m^3); at the end the
    axial and volumetric strain, sigma_1 and sigma_3 (Pa), q (Pa), q / p and the porosity; and
    the series with the q-p path (TriaxialSeries)."""

    simulation: Simulation
    top: float
    height: float
    volume: float
    axial_strain: float
    volumetric_strain: float
    axial_stress: float
    lateral_stress: float
    deviatoric_stress: float
    stress_ratio: float
    porosity: float
    series: TriaxialSeries = field(repr=False)


class _Path:
    """The example's strains (against references set after the isotropic phase) and rows."""

    def __init__(self):
        self.z_ref, self.height_ref, self.volume_ref = 0.0, 1.0, 1.0
        self.compressing = False
        self.rows = []

    def axial(self, s):
        return (self.z_ref - s.walls().position[TOP]) / self.height_ref

    def volumetric(self, s):
        return (self.volume_ref - box_volume(s)) / self.volume_ref

    def row(self, s):
        sigma_1, sigma_3 = s.wall_normal_stress(TOP), side_stress(s)
        p = s.porosity()
        nan = float("nan")
        self.rows.append((s.time, float(self.compressing), self.axial(s) if self.compressing else nan,
                          self.volumetric(s) if self.compressing else nan, sigma_1, sigma_3, sigma_1 - sigma_3,
                          (sigma_1 + 2 * sigma_3) / 3, p["porosity"], p["void_ratio"]))

    def series(self):
        c = np.array(self.rows, dtype=np.float64).reshape(-1, 10).T
        return TriaxialSeries(c[0], c[1] != 0, *c[2:])


def triaxial(particles=800, radius=0.01, spread=0.1, density=2500.0, k_n=1e5, friction=0.5, restitution=0.5, seed=1,
             wall_mass=0.1, confining=1e4, velocity=0.02, confine_duration=0.15, duration=0.3, output_interval=0.02,
             precision="double", checkpoint=None, verbose=True, sample=None):
    """The triaxial example: a sample (deposited_sample with side walls, or with `sample` the saved
    sample at that path, which must be closed by walls on x and y, as the example's --sample);
    the side walls and the upper wall held at `confining` (Pa, each wall's mass `wall_mass` times
    the particles') for `confine_duration` (s), then the upper wall moved down at `velocity`
    (m/s) for `duration` (s). Particle-wall contacts are frictional (frictional_wall_contact).
    Prints the example's lines when `verbose`, writes the final checkpoint to `checkpoint` when
    given, and returns a Triaxial, whose series has a row every `output_interval` (s). The
    options are the example's (triaxial --help: --confine-time is `confine_duration`, --time is
    `duration`), with the same defaults."""
    wall = frictional_wall_contact(radius, density, k_n, friction, restitution)
    sim = prepared_sample(sample, wall, verbose, side_walls=True, particles=particles, radius=radius, spread=spread,
                          density=density, k_n=k_n, friction=friction, restitution=restitution, seed=seed,
                          precision=precision)
    if verbose:
        print("triaxial: %d particles (%s), sample at t = %.3f s; porosity %.4f"
              % (sim.size, precision, sim.time, sim.porosity()["porosity"]))
    for f in (0, 1, 2, 3, TOP):
        sim.set_wall_control(f, stress_wall(sim, confining, wall_mass))

    # The example's rows: one now, then one at every multiple of the interval's steps.
    path = _Path()
    path.row(sim)
    first = sim.steps
    sim.add_observer(max(_steps_for(output_interval, sim.dt), 1), lambda s: s.steps != first and path.row(s))
    sim.run(_steps_for(confine_duration, sim.dt))

    path.z_ref = sim.walls().position[TOP]
    path.height_ref = path.z_ref - sim.walls().position[4]
    path.volume_ref = box_volume(sim)
    path.compressing = True
    if verbose:
        print("after the isotropic phase: axial %.1f Pa, lateral %.1f Pa, porosity %.4f"
              % (sim.wall_normal_stress(TOP), side_stress(sim), sim.porosity()["porosity"]))
    sim.set_wall_control(TOP, velocity_wall(velocity))
    sim.run(_steps_for(duration, sim.dt))

    sigma_1, sigma_3 = sim.wall_normal_stress(TOP), side_stress(sim)
    q, p = sigma_1 - sigma_3, (sigma_1 + 2 * sigma_3) / 3
    result = Triaxial(sim, path.z_ref, path.height_ref, path.volume_ref, path.axial(sim), path.volumetric(sim),
                      sigma_1, sigma_3, q, q / p, sim.porosity()["porosity"], path.series())
    if verbose:
        print("%-34s %14.6f" % ("axial strain", result.axial_strain))
        print("%-34s %14.6f" % ("volumetric strain", result.volumetric_strain))
        print("%-34s %14.1f" % ("axial stress sigma_1 (Pa)", sigma_1))
        print("%-34s %14.1f  (target %.1f)" % ("lateral stress sigma_3 (Pa)", sigma_3, confining))
        print("%-34s %14.1f" % ("deviatoric stress q (Pa)", q))
        print("%-34s %14.4f" % ("stress ratio q / p", q / p))
        print("%-34s %14.6f" % ("porosity", result.porosity))
    if checkpoint is not None:
        sim.write_checkpoint(checkpoint)
    return result
