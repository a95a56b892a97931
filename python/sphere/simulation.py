"""The class Simulation and checkpoints: sphere::simulation on the host backend with the linear
contact law, in float or double (docs/python.md)."""

import math
import os
import weakref

import numpy as np

from . import _sphere
from ._sphere import Error
from .fields import Contacts, Energy, Snapshot, Walls
from .settings import face_index

PRECISIONS = ("float", "double")

# Motion kinds (sphere::motion): a particle's code is its name's index here.
MOTION_KINDS = ("free", "prescribed", "fixed", "prescribed_horizontal")


def backend(precision):
    """The extension's submodule of a precision ('float' or 'double')."""
    if precision not in PRECISIONS:
        raise Error(f"sphere: precision = {precision!r}: not one of 'float', 'double'")
    return getattr(_sphere, precision)


def _per_particle(value, n):
    """A number or N numbers as an array of N doubles (the library checks the shape)."""
    a = np.asarray(value, dtype=np.float64)
    return np.full(n, a) if a.ndim == 0 else a


def _vectors(value, n):
    """None (zeros) or (N, 3) numbers as an array of doubles (the library checks the shape)."""
    return np.zeros((n, 3)) if value is None else np.asarray(value, dtype=np.float64)


def _kind_codes(kinds, fixed, n):
    """The motion kind codes of N particles from `kinds` (names or codes, one or N) or the mask
    `fixed` (True: 'fixed', False: 'free'); all free when both are None."""
    if kinds is not None and fixed is not None:
        raise Error("sphere: give kinds or fixed, not both")
    if fixed is not None:
        return np.where(np.asarray(fixed, dtype=bool), MOTION_KINDS.index("fixed"), 0).astype(np.uint8)
    if kinds is None:
        return np.zeros(n, dtype=np.uint8)
    given = np.asarray(kinds)
    codes = np.empty(given.shape, dtype=np.int64)
    for index, kind in np.ndenumerate(given):
        kind = kind.item()
        if kind in MOTION_KINDS:
            codes[index] = MOTION_KINDS.index(kind)
        elif isinstance(kind, int) and not isinstance(kind, bool) and 0 <= kind < len(MOTION_KINDS):
            codes[index] = kind
        else:
            raise Error(f"sphere: kinds{list(index)} = {kind!r}: not one of {', '.join(map(repr, MOTION_KINDS))} "
                        f"or a code 0 to {len(MOTION_KINDS) - 1}")
    return np.full(n, codes, dtype=np.uint8) if codes.ndim == 0 else codes.astype(np.uint8)


def _steps_for(seconds, dt):
    """The number of steps of dt in `seconds`, rounded to the nearest, halves up (as llround)."""
    exact = seconds / dt
    whole = math.floor(exact)
    return whole + (1 if exact - whole >= 0.5 else 0)


class Simulation:
    """A DEM simulation of spheres (``sphere::simulation`` with the linear contact law, host
    backend).

    Simulation(settings, positions, radii, density, velocities=None, angular_velocities=None,
    fixed=None, kinds=None, precision='double') builds one from a sphere.Settings and the
    particles: positions (N, 3) in m; radii (m) and density (kg/m^3), one number for all or N;
    velocities (m/s) and angular_velocities (rad/s), (N, 3) or None for rest; either fixed, N
    booleans (True: the particle never moves), or kinds, one or N motion kinds (names of
    sphere.MOTION_KINDS or their codes); precision 'float' or 'double'. The library checks
    everything and raises sphere.Error naming the first bad value.
    """

    def __init__(self, settings, positions, radii, density, velocities=None, angular_velocities=None, fixed=None,
                 kinds=None, precision="double"):
        positions = np.asarray(positions, dtype=np.float64)
        n = positions.shape[0] if positions.ndim == 2 else 0
        self._impl = backend(precision).Simulation(
            settings, positions, _per_particle(radii, n), _per_particle(density, n), _vectors(velocities, n),
            _vectors(angular_velocities, n), _kind_codes(kinds, fixed, n))
        self._precision = precision
        self._observing = False

    @classmethod
    def _wrap(cls, impl, precision):
        """A Simulation around a simulation of the extension."""
        sim = cls.__new__(cls)
        sim._impl = impl
        sim._precision = precision
        sim._observing = False
        return sim

    def __repr__(self):
        return (f"<sphere.Simulation: {self.size} particles, {self._precision}, {self.steps} steps, "
                f"t = {self.time:g} s>")

    def __len__(self):
        return self.size

    @property
    def precision(self):
        """'float' or 'double'."""
        return self._precision

    @property
    def size(self):
        """The number of particles."""
        return self._impl.size

    @property
    def time(self):
        """Simulated time (s): steps * dt."""
        return self._impl.time

    @property
    def steps(self):
        """Steps taken since the start (a restart continues the count)."""
        return self._impl.steps

    @property
    def dt(self):
        """The time step (s)."""
        return self._impl.dt

    @property
    def rebuilds(self):
        """How many times the neighbour grid and contact lists were built."""
        return self._impl.rebuilds

    @property
    def initial_overlap(self):
        """The deepest overlap the particles started with, as a fraction of the smaller radius."""
        return self._impl.initial_overlap

    @property
    def settings(self):
        """A copy of the settings the simulation runs with (dt: the time step in use). Changing
        it changes nothing: set_wall_control changes a wall's control."""
        return self._impl.settings

    def _refuse_in_observer(self, what):
        if self._observing:
            raise Error(f"sphere: {what}: called from an observer of this simulation, which may read it and change "
                        "its walls and velocities, but not run it or add observers")

    def run(self, steps):
        """Runs `steps` steps. An exception raised by an observer stops the run and reaches the
        caller; the simulation is then at the end of the step that called the observer."""
        self._refuse_in_observer("run")
        self._impl.run(steps)

    def run_for(self, seconds):
        """Runs for `seconds` of simulated time, rounded to the nearest whole number of steps;
        returns that number."""
        steps = _steps_for(seconds, self.dt)
        self.run(steps)
        return steps

    def add_observer(self, every, observer):
        """Calls observer(simulation) after every `every`-th step (when steps is a multiple of
        `every`). Observers are not stored in checkpoints."""
        self._refuse_in_observer("add_observer")
        # The extension holds the callback; a weak reference back to this object keeps the two
        # from forming a cycle that Python's garbage collector cannot see through.
        this = weakref.ref(self)

        def call():
            sim = this()
            sim._observing = True
            try:
                observer(sim)
            finally:
                sim._observing = False

        self._impl.add_observer(every, call)

    def snapshot(self):
        """Every particle field now: a sphere.Snapshot of copies in user order."""
        return Snapshot(**self._impl.snapshot())

    def walls(self):
        """The six wall faces now: a sphere.Walls of copies."""
        return Walls(**self._impl.walls())

    def contacts(self):
        """The contact lists now, with the last step's forces: a sphere.Contacts of copies."""
        return Contacts(**self._impl.contacts())

    def energy(self):
        """The energy budget now: a sphere.Energy."""
        return Energy(**self._impl.energy())

    def momentum(self):
        """Total linear momentum, sum m v (kg m/s), as an array of three."""
        return np.array(self._impl.momentum())

    def porosity(self):
        """Porosity of the particles between the walls (periodic axes: the whole period):
        a dict of porosity, void_ratio, solid_volume (m^3) and volume (m^3)."""
        return self._impl.porosity()

    def wall_normal_stress(self, face):
        """Normal stress (Pa, compressive positive) of the particles on a wall face (an index
        or a name in sphere.FACES) in the last step."""
        return self._impl.wall_normal_stress(face_index(face))

    def set_wall_control(self, face, control):
        """Makes a wall face (index or name) move as the sphere.WallControl says from the next
        step on."""
        self._impl.set_wall_control(face_index(face), control)

    def set_wall_position(self, face, position):
        """Moves a wall face (index or name) to `position` (m along its axis) and stops it."""
        self._impl.set_wall_position(face_index(face), position)

    def set_velocity(self, index, velocity, angular_velocity=(0.0, 0.0, 0.0)):
        """Sets the velocity (m/s) and angular velocity (rad/s) of the particle with user index
        `index` (a prescribed particle keeps them)."""
        self._impl.set_velocity(index, velocity, angular_velocity)

    def write_checkpoint(self, path):
        """Writes everything the simulation needs to continue to `path` (atomically)."""
        self._impl.write_checkpoint(os.fspath(path))

    def write_vtk(self, path):
        """Writes the particles to the VTK file `path` (.vtu, atomically; docs/io.md, *VTK
        files*): positions, radii, velocities and every other particle field, the time as field
        data, as the examples' frames. ParaView opens it."""
        self._impl.write_vtk(os.fspath(path))

    def render(self, path, method="pres", max_val=None, lower_cutoff=0.0):
        """Writes a picture of the particles to the PNG file `path` (atomically) with the
        library's ray tracer (sphere::render_png, docs/render.md), as the original sphere's
        render(): 800 x 800 pixels looking along +y, each particle coloured by `method`:
        'normal' (one colour), 'pres' (particle pressure, Pa; zeros without the energy audit),
        'vel' (speed, m/s), 'angvel' (angular speed, rad/s) or 'xdisp' (accumulated x
        displacement, m), on the jet colour map from `lower_cutoff` to `max_val` (in the
        method's unit; None: the largest value shown) with a colour bar; particles below
        `lower_cutoff` are not drawn. The file's text chunks name the method ('sphere field')
        and the range. Raises sphere.Error for an unknown method, a bad range, a file that
        cannot be written, or a build without libpng."""
        _sphere.render_png(self._impl, os.fspath(path), method, max_val, lower_cutoff)


def _written_precision(path):
    """The precision a checkpoint was written in ('double' where the header does not say: the
    library then reports what is wrong with the file)."""
    try:
        with open(path, "rb") as f:
            head = f.read(16)
    except OSError:
        return "double"
    if head[:8] != b"SPHERECK" or len(head) < 16:
        return "double"
    return "float" if int.from_bytes(head[12:16], "little") == 4 else "double"


def read_checkpoint(path, precision=None):
    """A Simulation continuing from the checkpoint at `path` (sphere::restart): in `precision`,
    by default the one it was written in. Continuing in the same precision gives the same bits
    as the run that wrote it (with the same thread count). Raises sphere.Error for a file the
    library refuses (missing, corrupt, written with another contact law)."""
    path = os.fspath(path)
    if precision is None:
        precision = _written_precision(path)
    return Simulation._wrap(backend(precision).Simulation.restart(path), precision)
