"""Preparing samples (the library's setup/packing.cuh and particles/distributions.cuh): radii
from distributions, regular and jittered cubic lattices, random non-overlapping packings, the world fitted to the particles and
deposition under gravity. Random choices follow a seed, with the same results as the C++
functions; arrays come back in the precision asked for (float32 or float64), as the C++
functions of that precision compute them.
"""

import numpy as np

from .simulation import backend


def uniform_radii(n, r_min, r_max, seed, precision="double"):
    """n radii (m) uniform in [r_min, r_max]."""
    return backend(precision).uniform_radii(n, r_min, r_max, seed)


def lognormal_radii(n, mean, stddev, seed, precision="double"):
    """n log-normal radii (m) with the given mean and standard deviation (m)."""
    return backend(precision).lognormal_radii(n, mean, stddev, seed)


def bimodal_radii(n, r_small, r_large, ratio, seed, precision="double"):
    """n radii of two sizes (m), the large population's volume about `ratio` times the small's."""
    return backend(precision).bimodal_radii(n, r_small, r_large, ratio, seed)


def random_packing(radii, settings, seed, gap=0.0, max_tries=10000, precision="double"):
    """Centres (N, 3) of spheres of the given radii placed at random without overlap (surfaces
    at least `gap` m apart) in the world box of `settings` (a sphere.Settings: lo, hi and
    boundary; on a periodic axis the centres fill [lo, hi)). Raises sphere.Error when a sphere
    cannot be placed in `max_tries` tries."""
    return backend(precision).random_packing(np.asarray(radii, dtype=np.float64), settings, seed, gap, max_tries)


def cubic_lattice(n, spacing, origin=(0.0, 0.0, 0.0), precision="double"):
    """Centres (N, 3) of an n = (nx, ny, nz) simple cubic lattice (the original's initGridPos):
    particle i + nx (j + ny k) at origin + ((i + 1/2) s_x, (j + 1/2) s_y, (k + 1/2) s_z) for the
    spacing s (m; one number or three), so spheres of radius s/2 touch each other and the
    lattice's box."""
    s = tuple(spacing) if np.ndim(spacing) else (spacing,) * 3
    nx, ny, nz = n
    return backend(precision).cubic_lattice(nx, ny, nz, s, tuple(origin))


def jittered_lattice(n, spacing, jitter, seed, origin=(0.0, 0.0, 0.0), precision="double"):
    """cubic_lattice with each centre moved by an offset uniform in [-jitter, jitter] (m) on
    every axis, following `seed` (the original's initRandomGridPos); spacing >= 2 r_max + 2 jitter
    keeps spheres of radius up to r_max apart."""
    nx, ny, nz = n
    return backend(precision).jittered_lattice(nx, ny, nz, spacing, jitter, seed, tuple(origin))


def fit_world(settings, positions, radii, margin=2.0, headroom=0.0, precision="double"):
    """Sizes the world box of `settings` to the particles, in place (sphere's
    initGridAndWorldsize): on every wall axis [min(x - r) - margin r_max, max(x + r) + margin
    r_max], `headroom` m more above on z, extended upwards to whole grid cells; periodic axes
    keep their extent. Sets settings.cell_size to 0 (automatic)."""
    positions = np.asarray(positions, dtype=np.float64)
    radii = np.asarray(radii, dtype=np.float64)
    settings.lo, settings.hi = backend(precision).fit_world(settings, positions, radii, margin, headroom)
    settings.cell_size = 0.0


def deposit(sim, kinetic_threshold, max_steps, check_every=100, min_time=-1.0):
    """Runs a Simulation with gravity until its particles are at rest: kinetic plus rotational
    energy, checked every `check_every` steps, below `kinetic_threshold` (J), and at least
    `min_time` s passed (negative: the time to fall freely across the world). Returns a dict
    of steps, time (s) and kinetic (J). Raises sphere.Error when `max_steps` steps are not
    enough."""
    sim._refuse_in_observer("deposit")
    return sim._impl.deposit(kinetic_threshold, max_steps, check_every, min_time)


def sample_top(sim):
    """The highest point of any particle, max(z + r) (m)."""
    s = sim.snapshot()
    return float(np.max(s.positions[:, 2].astype(np.float64) + s.radii.astype(np.float64)))

