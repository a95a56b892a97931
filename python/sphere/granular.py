"""The granular examples' sample preparation (examples/common/granular.hpp) as calls: their
contact parameters, a sample poured under gravity into a box periodic in x and y
(granular::deposited_sample), a saved sample to start from instead (the examples' --sample,
granular::prepared_sample) and the stress-controlled upper wall (granular::stress_wall). Every
value is computed in the same order as there, so that the experiments built on them
(consolidation.py, shear.py) give the examples' numbers to the last bit.
"""

import math
import os

import numpy as np

from ._sphere import gamma_n_from_restitution
from .samples import deposit, fit_world, random_packing, sample_top, uniform_radii
from .settings import ContactParams, Settings, WallControl
from .simulation import Simulation, backend

# The example's std::cbrt; math.cbrt (the C library's) exists from Python 3.11 on.
_cbrt = getattr(math, "cbrt", np.cbrt)

TOP = 5  # the upper wall's face (z+)


def sphere_mass(radius, density):
    """4/3 pi r^3 density (kg) of a sphere of `radius` (m) and `density` (kg/m^3), as
    sphere::sphere_mass computes it in double."""
    return 4.0 / 3.0 * math.pi * radius * radius * radius * density


def sample_contact(radius=0.01, density=2500.0, k_n=1e5, friction=0.5, restitution=0.5):
    """The granular examples' contact parameters (granular::contact_of): k_n (N/m), k_t = 2/7
    k_n, gamma_n (N s/m) for the restitution of two particles of the mean radius (m) and
    density (kg/m^3), no tangential viscosity, static = dynamic friction."""
    m = sphere_mass(radius, density)
    return ContactParams(k_n=k_n, k_t=k_n * 2 / 7, gamma_n=gamma_n_from_restitution(restitution, m / 2, k_n),
                         mu_s=friction, mu_d=friction)


def deposited_sample(particles=800, radius=0.01, spread=0.1, density=2500.0, k_n=1e5, friction=0.5, restitution=0.5,
                     seed=1, precision="double", wall=None, side_walls=False):
    """A sample poured under gravity (-z, 9.81 m/s^2) into a world periodic in x and y (or,
    with `side_walls`, closed by walls on every side), come to rest, with the upper wall moved
    down onto it (granular::deposited_sample): radii uniform in radius (1 +- spread) (m), random
    centres in a column about as wide as the settled sample will be tall, filled to a solid
    fraction of 0.25. With side walls, they start on the fitted column and the world extends
    half a width beyond them on x and y (room to move out). `wall`: the particle-wall
    ContactParams (by default those of the particles, sample_contact)."""
    r, r_max = radius, radius * (1 + spread)
    radii = uniform_radii(particles, r * (1 - spread), r_max, seed, precision)
    volume = 0.0
    for ri in radii.tolist():  # in order, as the example sums
        volume += 4.0 / 3.0 * math.pi * ri * ri * ri
    width = _cbrt(volume / 0.6)  # a settled sample (solid fraction ~0.6) as tall as wide
    fill_height = volume / (0.25 * width * width) + 2 * r_max
    sides = "wall" if side_walls else "periodic"
    s = Settings(lo=(0.0, 0.0, 0.0), hi=(width, width, fill_height), boundary=(sides, sides, "wall"))
    centres = random_packing(radii, s, seed + 1, 0.02 * r, 100000, precision)
    fit_world(s, centres, radii, 1.0, 0.0, precision)  # before the skin is set, as in the example
    fitted_lo, fitted_hi = tuple(s.lo), tuple(s.hi)
    if side_walls:  # the world half a width wider on each side, in the precision's arithmetic
        real = np.float32 if precision == "float" else np.float64
        half = real(width / 2)
        s.lo = tuple(float(real(v) - half) if a < 2 else v for a, v in enumerate(fitted_lo))
        s.hi = tuple(float(real(v) + half) if a < 2 else v for a, v in enumerate(fitted_hi))
    s.contact = sample_contact(radius, density, k_n, friction, restitution)
    s.wall = wall if wall is not None else sample_contact(radius, density, k_n, friction, restitution)
    s.gravity = (0.0, 0.0, -9.81)
    s.skin = 0.1 * r
    sim = Simulation(s, centres, radii, density, precision=precision)
    if side_walls:
        for a in range(2):
            sim.set_wall_position(2 * a, float(fitted_lo[a]))
            sim.set_wall_position(2 * a + 1, float(fitted_hi[a]))
    m = sphere_mass(r, density)
    deposit(sim, 1e-4 * particles * m * 9.81 * 2 * r, 2000000, 200)
    sim.set_wall_position(TOP, sample_top(sim))
    return sim


def saved_sample(path, wall, precision="double", verbose=True, side_walls=False):
    """A Simulation of the saved sample at `path` (a checkpoint: the final one of consolidate,
    shear or an example, or an example's sample.ck), as the granular examples start from one
    with --sample: its particles, contact parameters, world and wall positions, in
    `precision`; the particle-wall ContactParams `wall` (the experiment's own); every wall
    fixed until the experiment sets its controls. The sample must be periodic on x and y, or
    with `side_walls` closed by walls on x and y (sphere.Error otherwise). Prints the
    example's line ('sample: N particles from ...') when `verbose`."""
    path = os.fspath(path)
    sim = Simulation._wrap(backend(precision).simulation_of_sample(path, wall, side_walls), precision)
    if verbose:
        print("sample: %d particles from '%s' at t = %.6f s" % (sim.size, path, sim.time))
    return sim


def prepared_sample(sample, wall, verbose, side_walls=False, **deposition):
    """The sample an experiment starts from (granular::prepared_sample): saved_sample(sample,
    wall, ...) when `sample` is a path, else deposited_sample(**deposition, wall=wall), either
    with side walls or periodic on x and y."""
    if sample is not None:
        return saved_sample(sample, wall, deposition.get("precision", "double"), verbose, side_walls)
    return deposited_sample(wall=wall, side_walls=side_walls, **deposition)


def frictional_wall_contact(radius=0.01, density=2500.0, k_n=1e5, friction=0.5, restitution=0.5):
    """The particle-wall ContactParams of the examples with side walls
    (granular::frictional_wall_of): sample_contact's, with a tangential viscosity gamma_t =
    gamma_n (N s/m), so that the walls' friction acts (the wall law has no tangential force
    without it)."""
    c = sample_contact(radius, density, k_n, friction, restitution)
    c.gamma_t = c.gamma_n
    return c


def velocity_wall(velocity):
    """A wall control moving inwards at `velocity` (m/s) (granular::velocity_wall)."""
    return WallControl(mode="velocity", velocity=velocity)


def stress_wall(sim, stress, wall_mass=0.1, amplitude=0.0, frequency=0.0):
    """The upper wall's control holding the normal stress `stress` + `amplitude` sin(2 pi
    `frequency` t) (Pa, Hz) with a mass of `wall_mass` times the particles' total mass
    (granular::stress_wall): a wall that responds on the time scale of the sample it loads."""
    total_mass = 0.0
    for mi in sim.snapshot().masses.tolist():  # in order, as the example sums
        total_mass += mi
    return WallControl(mode="stress", stress=stress, mass=wall_mass * total_mass, amplitude=amplitude,
                       frequency=frequency)
