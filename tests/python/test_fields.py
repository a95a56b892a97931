"""Fields as NumPy arrays: user order, shapes and types, kinds, contact forces against k_n
times the overlap, walls, energies and settings."""

import math

import numpy as np
import pytest

import sphere
from conftest import eps, linear_settings

FIELDS_3 = ["positions", "velocities", "angular_velocities", "integrator_velocities", "integrator_angular_velocities",
            "angular_positions", "forces", "torques"]
FIELDS_1 = ["radii", "masses", "pressures", "dissipated_viscous", "dissipated_friction", "power_viscous",
            "power_friction"]


def lattice_sample(precision, **kw):
    """27 particles on a jittered 3 x 3 x 3 lattice under gravity, given in a shuffled order."""
    rng = np.random.default_rng(3)
    cells = np.array([[i, j, k] for i in range(3) for j in range(3) for k in range(3)], dtype=float)
    positions = (0.1 + 0.1 * cells + rng.uniform(-0.005, 0.005, cells.shape))[rng.permutation(27)]
    radii = rng.uniform(0.03, 0.04, 27)
    s = linear_settings(hi=(0.4, 0.4, 0.5), gravity=(0, 0, -9.81), skin=0.002)
    s.contact.gamma_n = s.wall.gamma_n = 5.0
    return sphere.Simulation(s, positions, radii, 2500, precision=precision, **kw), positions, radii


def test_snapshot_in_user_order(precision):
    sim, positions, radii = lattice_sample(precision)
    dtype = np.float32 if precision == "float" else np.float64
    snap = sim.snapshot()
    np.testing.assert_array_equal(snap.positions, positions.astype(dtype))
    sim.run(3000)  # the grid stores the particles in its own order as they fall and touch
    snap = sim.snapshot()
    assert len(snap) == 27
    np.testing.assert_array_equal(snap.radii, radii.astype(dtype))
    masses = 4 / 3 * math.pi * radii**3 * 2500
    np.testing.assert_allclose(snap.masses, masses, rtol=4 * eps(precision))
    for name in FIELDS_3:
        a = getattr(snap, name)
        assert a.shape == (27, 3) and a.dtype == dtype, name
    for name in FIELDS_1:
        a = getattr(snap, name)
        assert a.shape == (27,) and a.dtype == dtype, name
    assert snap.kinds.dtype == np.uint8 and not snap.kinds.any()
    assert snap.materials.dtype == np.uint8 and not snap.materials.any()
    assert snap.positions[:, 2].mean() < positions[:, 2].mean() - 0.01  # the sample fell
    assert (snap.pressures > 0).any() and (snap.dissipated_viscous > 0).any()
    assert not np.shares_memory(snap.positions, sim.snapshot().positions)  # copies


def test_fixed_and_kinds(precision):
    fixed = np.zeros(27, dtype=bool)
    fixed[[4, 20]] = True
    sim, positions, _ = lattice_sample(precision, fixed=fixed)
    sim.run(500)
    snap = sim.snapshot()
    assert snap.kinds.tolist() == [2 if f else 0 for f in fixed]
    dtype = np.float32 if precision == "float" else np.float64
    np.testing.assert_array_equal(snap.positions[fixed], positions[fixed].astype(dtype))
    kinds = ["free"] * 27
    kinds[7] = "fixed"
    sim, positions, _ = lattice_sample(precision, kinds=kinds)
    sim.run(500)
    assert sphere.MOTION_KINDS[sim.snapshot().kinds[7]] == "fixed"
    assert (sim.snapshot().positions[7] == positions[7].astype(dtype)).all()


def test_contact_forces_of_overlapping_particles(precision):
    # Particles 0 and 1 overlap by delta along x; particle 2 sits on the floor, overlapping it by
    # delta_w. In the first step the velocities are zero: f_n = k_n * overlap.
    k_n, r, delta, delta_w = 1e5, 0.01, 1e-4, 2e-4
    s = linear_settings(lo=(-0.1, -0.1, -0.1), hi=(0.1, 0.1, 0.1), k_n=k_n)
    positions = [[-r + delta / 2, 0, 0], [r - delta / 2, 0, 0], [0.05, 0.05, -0.1 + r - delta_w]]
    sim = sphere.Simulation(s, positions, r, 2500, precision=precision)
    sim.run(1)
    c = sim.contacts()
    tol = 1e-4 if precision == "float" else 1e-9  # the overlaps computed from positions in the precision
    assert c.pairs.tolist() == [[0, 1]]
    assert c.normal_force[0] == pytest.approx(k_n * delta, rel=tol)
    np.testing.assert_array_equal(c.tangential_force, np.zeros((1, 3)))
    assert c.force[0].tolist() == [-c.normal_force[0], 0, 0]  # on particle 0, away from particle 1
    assert c.touching.tolist() == [True]
    snap = sim.snapshot()
    np.testing.assert_array_equal(snap.forces[0], c.force[0])
    np.testing.assert_array_equal(snap.forces[1], -c.force[0])
    assert c.wall_particles.tolist() == [2] and c.wall_faces.tolist() == [4]
    assert c.wall_normal_force[0] == pytest.approx(k_n * delta_w, rel=tol)
    assert c.wall_force[0].tolist() == [0, 0, c.wall_normal_force[0]]
    walls = sim.walls()
    assert walls.force[4] == pytest.approx(-k_n * delta_w, rel=tol)
    assert sim.wall_normal_stress("z-") == pytest.approx(k_n * delta_w / 0.2**2, rel=tol)


def test_contacts_without_forces():
    s = linear_settings(contact_forces=False)
    sim = sphere.Simulation(s, [[0.5, 0.5, 0.5], [0.519, 0.5, 0.5]], 0.01, 2500)
    sim.run(1)
    c = sim.contacts()
    assert c.pairs.tolist() == [[0, 1]]
    assert c.normal_force is None and c.force is None and c.wall_force is None


def test_walls_energy_and_settings(precision):
    s = linear_settings(boundary=("periodic", "wall", "wall"), gravity=(0, 0, -9.81))
    s.walls[5] = sphere.WallControl(mode="velocity", velocity=0.01)
    sim = sphere.Simulation(s, [[0.5, 0.5, 0.25]], 0.01, 2500, precision=precision)
    walls = sim.walls()
    assert walls.active.tolist() == [False, False, True, True, True, True]
    assert walls.position.tolist() == [0, 1, 0, 1, 0, 1]
    assert walls.mode == ["fixed"] * 5 + ["velocity"]
    m = float(sim.snapshot().masses[0])
    energy = sim.energy()
    assert energy.potential == pytest.approx(m * 9.81 * 0.25, rel=4 * eps(precision))
    assert energy.kinetic == 0 and energy.total == energy.potential
    if precision == "double":
        assert sim.settings == s  # as given (dt = 0: the automatic time step, sim.dt)
    else:
        assert sim.settings.walls[5].velocity == float(np.float32(0.01))
    assert sim.settings.boundary == ("periodic", "wall", "wall")
