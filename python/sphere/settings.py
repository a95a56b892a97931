"""Settings of a simulation: the world box and its boundaries, the linear contact law's
parameters for particle pairs and for walls, gravity, the time step, the contact lists and the
walls' controls. They mirror the library's ``sphere::settings`` (include/sphere/settings.cuh);
values are SI units, and names of the library's enumerations are strings spelt as in C++.
Nothing is checked here: the simulation checks everything when it is built and raises
``sphere.Error`` naming the bad value.
"""

from dataclasses import dataclass, field

from ._sphere import Error

# Wall faces: face f lies on axis f // 2, at the lower end when f is even.
FACES = ("x-", "x+", "y-", "y+", "z-", "z+")


def face_index(face):
    """The index (0 to 5) of a wall face given as an index or as a name in FACES ('z+' is 5)."""
    if isinstance(face, str):
        if face not in FACES:
            raise Error(f"sphere: face {face!r}: not one of {', '.join(map(repr, FACES))} or an index 0 to 5")
        return FACES.index(face)
    return face


@dataclass
class ContactParams:
    """The linear contact law's parameters (``sphere::contact_params``).

    k_n, k_t: normal and tangential stiffness (N/m).
    gamma_n, gamma_t: normal and tangential viscosity, in the units of ``damping``:
        'absolute' (N s/m, the same for every contact, sphere's convention), 'mass_scaled'
        (1/s, times the contact's effective mass: LAMMPS gran/hooke) or 'damping_ratio'
        (fractions of critical damping).
    mu_s, mu_d: static and dynamic friction coefficients (0 <= mu_d <= mu_s).
    tension: allow an attractive normal force (False: clipped at zero, as sphere does).
    For walls (Settings.wall), gamma_n, gamma_t, mu_s and mu_d are sphere's gamma_wn,
    gamma_wt, mu_ws and mu_wd.
    """

    k_n: float = 0.0
    k_t: float = 0.0
    gamma_n: float = 0.0
    gamma_t: float = 0.0
    mu_s: float = 0.0
    mu_d: float = 0.0
    tension: bool = False
    damping: str = "absolute"


@dataclass
class WallControl:
    """How one wall face moves (``sphere::wall_control``); along the face's inward normal.

    mode: 'fixed', 'velocity' (moves inwards at ``velocity``, m/s) or 'stress' (a wall of
        ``mass`` kg pushed inwards by the normal stress stress + amplitude
        sin(2 pi frequency t + phase), Pa, and pushed back by the particles).
    """

    mode: str = "fixed"
    velocity: float = 0.0
    stress: float = 0.0
    amplitude: float = 0.0
    frequency: float = 0.0
    phase: float = 0.0
    mass: float = 0.0


def _fixed_walls():
    return [WallControl() for _ in FACES]


@dataclass
class Settings:
    """Everything a simulation needs besides its particles (``sphere::settings``).

    lo, hi: the world box's corners (m).
    boundary: per axis x, y, z, 'wall' (planar walls at lo and hi) or 'periodic'.
    contact: ContactParams of particle pairs; wall: ContactParams of particle-wall contacts.
    gravity: (m/s^2).
    dt: time step (s); 0 selects the contact law's rule (0.075 min sqrt(m / max(k_n, k_t))).
    skin: contact-list skin (m); 0 rebuilds the lists every step.
    max_initial_overlap: the deepest overlap particles may start with, as a fraction of the
        smaller radius.
    cell_size: neighbour-grid cell width (m); 0 selects the largest diameter plus the skin.
    contact_forces: keep each contact's force of the last step (Simulation.contacts()).
    energy_audit: book the dissipated energies every step (Simulation.energy() closes).
    angular_position: integrate each particle's angular position.
    accumulated_displacement: integrate each particle's displacement since the start (m, sum of
        v dt, unwrapped across periodic boundaries: the original's xysum).
    reorder: store the particles in the grid's cell order (the same results either way).
    pair_summation: 'automatic', 'slabs' or 'gather' (docs/architecture.md).
    walls: six WallControls, faces x-, x+, y-, y+, z-, z+ (FACES); all fixed by default.
    The parallel bonds' parameters (settings.bond in C++) are not available from Python yet.
    """

    lo: tuple = (0.0, 0.0, 0.0)
    hi: tuple = (1.0, 1.0, 1.0)
    boundary: tuple = ("wall", "wall", "wall")
    contact: ContactParams = field(default_factory=ContactParams)
    wall: ContactParams = field(default_factory=ContactParams)
    gravity: tuple = (0.0, 0.0, 0.0)
    dt: float = 0.0
    skin: float = 0.0
    max_initial_overlap: float = 0.5
    cell_size: float = 0.0
    contact_forces: bool = True
    energy_audit: bool = True
    angular_position: bool = True
    accumulated_displacement: bool = True
    reorder: bool = True
    pair_summation: str = "automatic"
    walls: list = field(default_factory=_fixed_walls)


@dataclass
class FluidBoundary:
    """One z end of the fluid grid (``sphere::fluid_boundary``).

    kind: 'no_flow' (an impermeable, free-slip wall at the grid's face), 'pressure' (the
        pressure pressure + amplitude sin(2 pi frequency t + phase), Pa, held at the centres of
        the outermost cell layer: drained) or 'inflow' (the superficial velocity ``velocity``,
        m/s along +z, through the grid's face; the other end must be 'pressure').
    """

    kind: str = "no_flow"
    pressure: float = 0.0
    amplitude: float = 0.0
    frequency: float = 0.0
    phase: float = 0.0
    velocity: float = 0.0


@dataclass
class FluidSettings:
    """The pore fluid and its coupling to the particles (``sphere::fluid_params``,
    ``sphere::darcy_params``, ``sphere::coupling_options``; docs/fluid.md).

    model: 'navier_stokes' (the porosity-weighted Navier-Stokes equations, with the Gidaspow
        drag law) or 'darcy' (the pore pressure alone, Darcy's law with Kozeny-Carman
        permeability).
    solver: the pressure solver, 'mg' (conjugate gradients with a multigrid preconditioner) or
        'cg' (plain conjugate gradients).
    density (kg/m^3), viscosity (Pa s): water at 25 C by default.
    beta: weight of the old pressure in the projection, 0 (Chorin) to 1 (Navier-Stokes).
    gravity: (m/s^2); None takes the simulation's.
    bottom, top: FluidBoundary of the z = lo and z = hi ends.
    tolerance, max_iterations, criterion: the pressure solve's ('relative_residual' or
        'normalized_change'); use a tolerance near 1e-4 in float.
    compressibility (1/Pa), permeability_prefactor (m^2, k_c of k = k_c phi^3 / (1 - phi)^2:
        d^2/180 for spheres of diameter d; no default), max_porosity: the Darcy model's.
    dem_steps: DEM steps per fluid step (the fluid step is dem_steps times the DEM step).
    pressure_force: apply -V grad p to the particles (buoyancy and the pressure gradient).
    porosity: how the cells' solid volume is measured, 'cell_volume' (conserves it) or
        'cell_sphere' (the original's estimator).
    """

    model: str = "navier_stokes"
    solver: str = "mg"
    density: float = 997.05
    viscosity: float = 8.90e-4
    beta: float = 0.0
    gravity: tuple = None
    bottom: FluidBoundary = field(default_factory=FluidBoundary)
    top: FluidBoundary = field(default_factory=FluidBoundary)
    tolerance: float = 1e-8
    max_iterations: int = 100000
    criterion: str = "relative_residual"
    compressibility: float = 4.5e-10
    permeability_prefactor: float = 0.0
    max_porosity: float = 0.9
    dem_steps: int = 10
    pressure_force: bool = True
    porosity: str = "cell_volume"
