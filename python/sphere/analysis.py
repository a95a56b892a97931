"""Analyses of a simulation's state as NumPy values (include/sphere/analysis/): porosity in a
box and against depth, the stresses (on the walls, the Love-Weber tensor of the assembly), the
contact network (force chains, coordination numbers), the orientation of axes as trend and
plunge and their rose histogram, and a shear-strain tracker. All computed in double (SI units),
from the last step's forces and the positions after it (exact for a static assembly). The
contact analyses need settings.contact_forces (the default); sphere.Error otherwise.
"""

from dataclasses import dataclass

import numpy as np

from . import _sphere
from .simulation import backend


def _ext(sim):
    return backend(sim.precision)


def porosity(sim, lo=None, hi=None):
    """Porosity of the particles in the box [lo, hi] (m, three numbers each; on a periodic axis
    within one period, the particles' periodic images counted), by default between the walls
    (the whole period on periodic axes; sphere's bulkPorosity). The solid volume is exact (each
    sphere cut by the box's planes). Returns a dict of `porosity`, `void_ratio`, `solid_volume`
    (m^3) and `volume` (m^3)."""
    if lo is None and hi is None:
        return sim.porosity()
    if lo is None or hi is None:
        raise _sphere.Error("sphere: porosity: give both lo and hi, or neither")
    return _ext(sim).porosity_in_box(sim._impl, lo, hi)


@dataclass
class PorosityProfile:
    """Porosity against height: slice k spans z_lo[k] to z_hi[k] (m), bottom first, and has
    porosity[k]; z is each slice's middle (m)."""

    z_lo: np.ndarray
    z_hi: np.ndarray
    porosity: np.ndarray

    @property
    def z(self):
        return (self.z_lo + self.z_hi) / 2


def porosity_profile(sim, slices=10, lo=None, hi=None):
    """The porosity in `slices` horizontal slices of equal height (sphere's porosity(slices)) of
    the box [lo, hi] (m), by default the space between the walls (the whole period on periodic
    axes). Returns a PorosityProfile."""
    if (lo is None) != (hi is None):
        raise _sphere.Error("sphere: porosity_profile: give both lo and hi, or neither")
    return PorosityProfile(*_ext(sim).porosity_profile(sim._impl, slices, lo, hi))


def void_ratio(porosity_value):
    """Void ratio e = phi / (1 - phi) of a porosity phi (NumPy arrays too); infinite at 1."""
    phi = np.asarray(porosity_value, dtype=np.float64)
    with np.errstate(divide="ignore"):
        return phi / (1 - phi)


def wall_stresses(sim):
    """The particles' normal stress on each of the six walls (Pa, compressive positive; face
    order x-, x+, y-, y+, z-, z+), NaN on periodic axes."""
    active = sim.walls().active
    return np.array([sim.wall_normal_stress(f) if active[f] else np.nan for f in range(6)])


def stress_tensor(sim, volume=None):
    """The assembly's stress tensor (3, 3) (Pa, compressive positive) by the Love-Weber sum over
    contacts, sigma_ij = -(1/V) sum_c f_i^c l_j^c (pairs and wall contacts, l the branch vector
    from a centre to the contact point), over the volume V (m^3), by default that between the
    walls (the period on periodic axes, volume_between_walls)."""
    return _ext(sim).love_weber_stress(sim._impl, volume)


def volume_between_walls(sim):
    """Volume (m^3) between the walls: the wall distance on wall axes, the period on periodic
    ones."""
    return _ext(sim).volume_between_walls(sim._impl)


def contact_counts(sim, with_walls=False):
    """Each particle's number of contacts that carried a force in the last step (its touching
    pairs, plus its wall contacts when `with_walls`), in user order."""
    return _ext(sim).contact_counts(sim._impl, with_walls)


def coordination(sim, with_walls=False):
    """Mean coordination number: 2 touching pairs / N (plus wall contacts / N when
    `with_walls`)."""
    return _ext(sim).mean_coordination(sim._impl, with_walls)


@dataclass
class ForceChains:
    """The contact network (sphere's forcechains): every pair that carried a force in the last
    step, once, i < j (user indices); centres x_i, x_j (M, 3) (m; x_j as stored, inside the
    period), the branch vector x_j - x_i to the nearest periodic image (m), the normal force
    (N, positive when repulsive) and the tangential force on i (M, 3) (N)."""

    i: np.ndarray
    j: np.ndarray
    x_i: np.ndarray
    x_j: np.ndarray
    branch: np.ndarray
    normal: np.ndarray
    tangential: np.ndarray

    def __len__(self):
        return len(self.i)


def force_chains(sim):
    """The contact network of the last step, a ForceChains."""
    return ForceChains(**_ext(sim).contact_network(sim._impl))


def orientations(axes):
    """Trend and plunge (degrees) of axes (M, 3), as a geologist gives a line: the trend
    clockwise from +y to the horizontal projection, in [0, 360), the plunge below the
    horizontal, in [0, 90], of the axis pointing down (a horizontal axis is taken with a trend
    below 180). Returns (trend, plunge)."""
    a = np.asarray(axes, dtype=np.float64)
    return _sphere.orientations(a.reshape(0, 3) if a.size == 0 else a)


@dataclass
class Rose:
    """A rose histogram: counts of axes by trend in equal sectors of [0, 360) degrees
    (`trend`, edges `trend_edges`) and by plunge in equal bins of [0, 90] degrees (`plunge`,
    edges `plunge_edges`)."""

    trend: np.ndarray
    plunge: np.ndarray
    trend_edges: np.ndarray
    plunge_edges: np.ndarray


def rose(trend, plunge, trend_bins=36, plunge_bins=9):
    """The Rose of orientations (degrees) given by trend and plunge (bond_rose.cuh, rose_of)."""
    t, p = _sphere.rose(np.asarray(trend, dtype=np.float64), np.asarray(plunge, dtype=np.float64), trend_bins,
                        plunge_bins)
    return Rose(t, p, np.linspace(0, 360, trend_bins + 1), np.linspace(0, 90, plunge_bins + 1))


def contact_rose(sim, trend_bins=36, plunge_bins=9):
    """The Rose of the force chains' branch vectors (the contact fabric; the original sphere's
    rose diagram of contacts)."""
    return rose(*orientations(force_chains(sim).branch), trend_bins, plunge_bins)


class ShearTracker:
    """Follows the shear strain of a shear cell (sphere::shear_tracker, sphere's shearStrain)
    from the simulation's current state on: its layers are the prescribed (top) and fixed
    (bottom) particles; strain = (mean displacement of the top layer less the bottom's along
    `axis`, 0 = x or 1 = y, periodic wraps unfolded) / (height between the layers' mean
    centres). Call update() at least once per interval in which no layer particle moves half a
    period. Raises sphere.Error without both layers."""

    def __init__(self, sim, axis=0):
        self._sim = sim
        self._impl = _ext(sim).ShearTracker(sim._impl, axis)

    def update(self):
        """Adds each layer particle's move since the last update."""
        self._impl.update(self._sim._impl)

    strain = property(lambda self: self._impl.strain, doc="shear strain at the last update")
    displacement = property(lambda self: self._impl.displacement, doc="top less bottom mean displacement (m)")
    height = property(lambda self: self._impl.height, doc="height between the layers at the last update (m)")
    velocity = property(lambda self: self._impl.velocity, doc="shear velocity at the last update (m/s)")
    strain_rate = property(lambda self: self._impl.strain_rate, doc="velocity / height (1/s)")

    @property
    def layers(self):
        """The layers' user indices: dict of `top` and `bottom` lists."""
        return self._impl.layers
