"""What a simulation hands out: its particles, walls, contacts and energies at one moment.

Every array is a copy (the library stores its particles in the neighbour grid's order, which
changes as they move): changing one changes nothing in the simulation, and it does not follow
the simulation as it runs. Particle arrays are in user order: row i belongs to the i-th
particle given to Simulation (its *user index*, which every message of the library uses too).
Particle values are in the simulation's precision (float32 or float64); the walls' are float64.
"""

from dataclasses import dataclass

import numpy as np


@dataclass
class Snapshot:
    """Every particle field (``sphere::particle_snapshot``), copies in user order.

    positions (N, 3): centres (m). radii (N,): (m). masses (N,): (kg).
    velocities, angular_velocities (N, 3): (m/s, rad/s) at the time of the positions, as the
        VTK files and the energies use them.
    integrator_velocities, integrator_angular_velocities (N, 3): the integrator's own
        velocities (semi-implicit Euler: those of the last position update, half a step away
        from the positions' time).
    angular_positions (N, 3): integrated rotation (rad); zero without settings.angular_position.
    displacements (N, 3): accumulated displacement since the start, sum of v dt (m), unwrapped
        across periodic boundaries (the original's xysum); zero without
        settings.accumulated_displacement.
    forces, torques (N, 3): sums of the contact forces (N) and torques (N m) of the last step,
        gravity left out.
    pressures (N,): the normal contact forces' magnitudes summed over the surface (Pa).
    dissipated_viscous, dissipated_friction (N,): energy dissipated so far (J);
    power_viscous, power_friction (N,): their rates in the last step (W); these four and the
        pressures are zero without settings.energy_audit.
    kinds (N,): motion kind codes, indices into sphere.MOTION_KINDS (0 free, 1 prescribed,
        2 fixed, 3 prescribed_horizontal). materials (N,): material indices (0 with the
        linear law).
    """

    positions: np.ndarray
    radii: np.ndarray
    velocities: np.ndarray
    angular_velocities: np.ndarray
    integrator_velocities: np.ndarray
    integrator_angular_velocities: np.ndarray
    angular_positions: np.ndarray
    displacements: np.ndarray
    forces: np.ndarray
    torques: np.ndarray
    masses: np.ndarray
    pressures: np.ndarray
    dissipated_viscous: np.ndarray
    dissipated_friction: np.ndarray
    power_viscous: np.ndarray
    power_friction: np.ndarray
    kinds: np.ndarray
    materials: np.ndarray

    def __len__(self):
        return len(self.radii)


@dataclass
class Walls:
    """The six wall faces (x-, x+, y-, y+, z-, z+, sphere.FACES), copies as arrays of six.

    position: each plane's coordinate along its axis (m). velocity: along the axis (m/s).
    force: the particles' force on the wall along its axis in the last step (N).
    work: work the wall has done on the particles so far (J).
    active: True on wall axes, False on periodic ones (whose faces are no walls).
    mode: each face's control mode ('fixed', 'velocity' or 'stress'; the whole controls are
        Simulation.settings.walls).
    """

    position: np.ndarray
    velocity: np.ndarray
    force: np.ndarray
    work: np.ndarray
    active: np.ndarray
    mode: list


@dataclass
class Contacts:
    """The contact lists (copies): every particle pair within reach of contact (touching, or
    within the skin), and every particle near a wall.

    pairs (M, 2): user indices (i, j), i < j, each pair once.
    wall_particles (K,), wall_faces (K,): the particle and the wall face of each wall entry.
    With settings.contact_forces (else None), the forces of the last step on particle i of
    each pair (on the particle of each wall entry):
    normal_force (M,): f_n (N) along the unit vector from j towards i (positive pushes i
        away), taken at the current positions (the wall's inward normal for walls).
    tangential_force (M, 3): the friction force (N). force (M, 3): their sum (N).
    touching (M,): whether the entry carried a force in the last step.
    wall_normal_force, wall_tangential_force, wall_force, wall_touching: the same for the
    wall entries.
    """

    pairs: np.ndarray
    wall_particles: np.ndarray
    wall_faces: np.ndarray
    normal_force: np.ndarray
    tangential_force: np.ndarray
    force: np.ndarray
    touching: np.ndarray
    wall_normal_force: np.ndarray
    wall_tangential_force: np.ndarray
    wall_force: np.ndarray
    wall_touching: np.ndarray


@dataclass
class Energy:
    """The energy budget (``sphere::energy_budget``, J; rates in W), summed in an order that
    does not depend on where particles are stored.

    kinetic, rotational, potential (-m g . x, zero at the origin), elastic (the contact
    springs), dissipated_viscous, dissipated_friction (so far), rate_viscous, rate_friction
    (in the last step), boundary_work (done on the particles by moving walls and driven
    particles), bond_elastic, bond_broken (bonds, none from Python yet), and total: mechanical
    energy plus everything dissipated less the boundary work, which stays constant.
    """

    kinetic: float
    rotational: float
    potential: float
    elastic: float
    dissipated_viscous: float
    dissipated_friction: float
    rate_viscous: float
    rate_friction: float
    boundary_work: float
    bond_elastic: float
    bond_broken: float
    total: float
