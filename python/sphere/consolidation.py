"""The C++ consolidation example (examples/consolidation/main.cpp) as calls: a sample poured
under gravity into a box periodic in x and y (granular::deposited_sample of
examples/common/granular.hpp), then loaded by the upper wall at a normal stress, optionally
sine-modulated (sphere's consolidate()). The same options give the example's numbers to the
last bit, in the same precision and with the same thread count: every value below is computed
in the same order as there (and, where the example casts to its precision, by the library).
"""

import math
from dataclasses import dataclass

import numpy as np

from ._sphere import gamma_n_from_restitution
from .samples import deposit, fit_world, random_packing, sample_top, uniform_radii
from .settings import ContactParams, Settings, WallControl
from .simulation import Simulation

# The example's std::cbrt; math.cbrt (the C library's) exists from Python 3.11 on.
_cbrt = getattr(math, "cbrt", np.cbrt)

TOP = 5  # the upper wall's face (z+)


def _sphere_mass(radius, density):
    """4/3 pi r^3 density (kg), as sphere::sphere_mass computes it in double."""
    return 4.0 / 3.0 * math.pi * radius * radius * radius * density


def sample_contact(radius=0.01, density=2500.0, k_n=1e5, friction=0.5, restitution=0.5):
    """The granular examples' contact parameters (granular::contact_of): k_t = 2/7 k_n,
    gamma_n for the restitution of two particles of the mean radius, no tangential viscosity,
    static = dynamic friction."""
    m = _sphere_mass(radius, density)
    return ContactParams(k_n=k_n, k_t=k_n * 2 / 7, gamma_n=gamma_n_from_restitution(restitution, m / 2, k_n),
                         mu_s=friction, mu_d=friction)


def deposited_sample(particles=800, radius=0.01, spread=0.1, density=2500.0, k_n=1e5, friction=0.5, restitution=0.5,
                     seed=1, precision="double"):
    """A sample poured under gravity (-z, 9.81 m/s^2) into a world periodic in x and y, come to
    rest, with the upper wall moved down onto it (granular::deposited_sample without side
    walls): radii uniform in radius (1 +- spread) (m), random centres in a column about as wide
    as the settled sample will be tall, filled to a solid fraction of 0.25."""
    r, r_max = radius, radius * (1 + spread)
    radii = uniform_radii(particles, r * (1 - spread), r_max, seed, precision)
    volume = 0.0
    for ri in radii.tolist():  # in order, as the example sums
        volume += 4.0 / 3.0 * math.pi * ri * ri * ri
    width = _cbrt(volume / 0.6)  # a settled sample (solid fraction ~0.6) as tall as wide
    fill_height = volume / (0.25 * width * width) + 2 * r_max
    s = Settings(lo=(0.0, 0.0, 0.0), hi=(width, width, fill_height), boundary=("periodic", "periodic", "wall"))
    centres = random_packing(radii, s, seed + 1, 0.02 * r, 100000, precision)
    fit_world(s, centres, radii, 1.0, 0.0, precision)  # before the skin is set, as in the example
    s.contact = sample_contact(radius, density, k_n, friction, restitution)
    s.wall = sample_contact(radius, density, k_n, friction, restitution)
    s.gravity = (0.0, 0.0, -9.81)
    s.skin = 0.1 * r
    sim = Simulation(s, centres, radii, density, precision=precision)
    m = _sphere_mass(r, density)
    deposit(sim, 1e-4 * particles * m * 9.81 * 2 * r, 2000000, 200)
    sim.set_wall_position(TOP, sample_top(sim))
    return sim


@dataclass
class Consolidation:
    """What consolidate() found: the simulation at the end, the deposition's duration (s), the
    sample's top and porosity before loading (m), the upper wall's final position (m), the
    compression of the sample (m), the final porosity and void ratio, and the wall's mean
    normal stress over the second half of the loading (Pa)."""

    simulation: Simulation
    deposition_time: float
    sample_top: float
    initial_porosity: float
    wall_position: float
    compression: float
    porosity: float
    void_ratio: float
    mean_stress: float


def consolidate(particles=800, radius=0.01, spread=0.1, density=2500.0, k_n=1e5, friction=0.5, restitution=0.5,
                seed=1, wall_mass=0.1, stress=1e4, amplitude=0.0, frequency=0.0, duration=0.4, precision="double",
                checkpoint=None, verbose=True):
    """The consolidation example: deposited_sample(...), then the upper wall held at the normal
    stress `stress` + `amplitude` sin(2 pi `frequency` t) (Pa) for `duration` s, the wall's mass
    `wall_mass` times the particles'. Prints the example's lines when `verbose`, writes the
    final checkpoint to `checkpoint` when given, and returns a Consolidation. The options are
    the example's (consolidation --help), with the same defaults."""
    sim = deposited_sample(particles, radius, spread, density, k_n, friction, restitution, seed, precision)
    z0 = sim.walls().position[TOP]
    initial = sim.porosity()["porosity"]
    if verbose:
        print("consolidation: %d particles (%s), sample at t = %.3f s; sample top at %.6f m, porosity %.4f"
              % (sim.size, precision, sim.time, z0, initial))
    deposition_time = sim.time

    total_mass = 0.0
    for mi in sim.snapshot().masses.tolist():  # in order, as the example sums
        total_mass += mi
    sim.set_wall_control(TOP, WallControl(mode="stress", stress=stress, mass=wall_mass * total_mass,
                                          amplitude=amplitude, frequency=frequency))

    # The time-average of the wall stress over the second half of the loading.
    t_half = sim.time + duration / 2
    stresses = []

    def second_half(s):
        if s.time >= t_half:
            stresses.append(s.wall_normal_stress(TOP))

    sim.add_observer(1, second_half)
    sim.run_for(duration)

    stress_sum = 0.0
    for value in stresses:  # in order, as the example sums
        stress_sum += value
    p = sim.porosity()
    wall = sim.walls().position[TOP]
    result = Consolidation(sim, deposition_time, z0, initial, wall, z0 - wall, p["porosity"], p["void_ratio"],
                           stress_sum / len(stresses))
    if verbose:
        print("%-34s %14.6f" % ("upper wall position (m)", result.wall_position))
        print("%-34s %14.6e" % ("compression of the sample (m)", result.compression))
        print("%-34s %14.6f" % ("porosity", result.porosity))
        print("%-34s %14.6f" % ("void ratio", result.void_ratio))
        print("%-34s %14.1f  (target %.1f)" % ("mean wall stress, 2nd half (Pa)", result.mean_stress, stress))
    if checkpoint is not None:
        sim.write_checkpoint(checkpoint)
    return result
