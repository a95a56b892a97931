"""Running a simulation from Python: free fall and a two-particle collision against their
closed forms, observers, run_for, wall controls and checkpoints of a Python-built run."""

import math

import numpy as np
import pytest

import sphere
from conftest import eps, linear_settings

G = 9.81


def test_free_fall(precision):
    # Semi-implicit Euler: v_n = -g n dt, z_n = z0 - g dt^2 n (n + 1) / 2 = z0 - g t^2 / 2 - g t dt / 2.
    z0 = 1.0
    s = linear_settings(lo=(0, 0, 0), hi=(1, 1, 2), gravity=(0, 0, -G))
    sim = sphere.Simulation(s, [[0.5, 0.5, z0]], 0.01, 2500, precision=precision)
    steps = 2000
    sim.run(steps)
    t, dt = sim.time, sim.dt
    assert sim.steps == steps and t == steps * dt
    z = float(sim.snapshot().positions[0, 2])
    # One rounding of z per step at most: steps * eps(z0).
    assert abs(z - (z0 - G * t * t / 2 - G * t * dt / 2)) <= steps * eps(precision) * z0
    # Against the exact motion the integrator is first order: g t dt / 2, plus the rounding.
    assert abs(z - (z0 - G * t * t / 2)) <= G * t * dt / 2 + steps * eps(precision) * z0
    assert z0 - z > 0.01  # it did fall (t = 0.05 s)
    assert sim.snapshot().positions[0, :2].tolist() == [0.5, 0.5]
    # The accumulated displacement is the sum of the same steps: the fall, to the rounding.
    d = sim.snapshot().displacements[0]
    assert d[0] == 0 and d[1] == 0
    assert abs(float(d[2]) - (z - z0)) <= steps * eps(precision) * z0
    assert sim.settings.accumulated_displacement


def collision(precision, restitution):
    """Two spheres of different sizes meeting head-on along x, frictionless, with gamma_n for
    the restitution coefficient; returns the simulation and the initial velocities."""
    r1, r2, rho, k_n = 0.01, 0.015, 2500.0, 1e5
    m1, m2 = 4 / 3 * math.pi * r1**3 * rho, 4 / 3 * math.pi * r2**3 * rho
    s = linear_settings(k_n=k_n)
    s.contact.gamma_n = sphere.gamma_n_from_restitution(restitution, m1 * m2 / (m1 + m2), k_n)
    v = [[0.5, 0, 0], [-0.3, 0, 0]]
    sim = sphere.Simulation(s, [[0.4, 0.5, 0.5], [0.45, 0.5, 0.5]], [r1, r2], rho, velocities=v, precision=precision)
    return sim, np.array(v)


def test_collision_conserves_momentum_with_the_restitution_asked_for(precision):
    sim, v0 = collision(precision, 0.8)
    m = sim.snapshot().masses.astype(np.float64)
    p0 = m @ v0
    e0 = sim.energy().total
    sim.run_for(0.1)  # contact at 0.031 s, lasting about 3 ms
    s = sim.snapshot()
    v = s.velocities.astype(np.float64)
    # Pair forces are equal and opposite: momentum changes only by rounding (measured: 1.5 eps).
    scale = float(np.abs(m) @ np.abs(v0[:, 0]))
    np.testing.assert_allclose(sim.momentum(), p0, rtol=0, atol=20 * eps(precision) * scale)
    np.testing.assert_allclose(m @ v, p0, rtol=0, atol=20 * eps(precision) * scale)
    # Restitution within 0.5% (the time step resolves the contact in about 120 steps; measured 0.7985).
    e = -(v[1, 0] - v[0, 0]) / (v0[1, 0] - v0[0, 0])
    assert e == pytest.approx(0.8, abs=0.004)
    assert not sim.contacts().touching.any()
    # The energy budget closes: what the dashpot took is what the motion lost, to the time
    # discretisation of the booked dissipation (measured: 8e-4 of the total).
    # The relative motion's energy, m_eff (v1 - v2)^2 / 2, loses the fraction 1 - e^2.
    lost = (1 - 0.8**2) * m[0] * m[1] / (m[0] + m[1]) * (v0[0, 0] - v0[1, 0]) ** 2 / 2
    energy = sim.energy()
    assert energy.kinetic == pytest.approx(e0 - lost, rel=0.01)
    assert energy.dissipated_viscous == pytest.approx(lost, rel=0.01)
    assert energy.total == pytest.approx(e0, rel=2e-3)


def test_observers(precision):
    sim, _ = collision(precision, 0.5)
    seen = []
    sim.add_observer(3, lambda s: seen.append((s is sim, s.steps)))
    sim.run(10)
    assert seen == [(True, 3), (True, 6), (True, 9)]

    def stop_at_12(s):
        if s.steps == 12:
            raise ValueError("stop")

    sim.add_observer(1, stop_at_12)
    with pytest.raises(ValueError, match="stop"):
        sim.run(10)
    assert sim.steps == 12
    sim.run(1)  # the simulation goes on from there
    assert sim.steps == 13


def test_observers_may_not_run_the_simulation():
    sim, _ = collision("double", 0.5)
    sim.add_observer(1, lambda s: s.run(1))
    with pytest.raises(sphere.Error, match="sphere: run: called from an observer of this simulation"):
        sim.run(1)


def test_run_for_rounds_to_whole_steps():
    sim, _ = collision("double", 0.5)
    assert sim.run_for(10.4 * sim.dt) == 10
    assert sim.run_for(10.6 * sim.dt) == 11
    assert sim.steps == 21


def test_wall_position_and_velocity_control(precision):
    s = linear_settings(hi=(1, 1, 1))
    sim = sphere.Simulation(s, [[0.5, 0.5, 0.2]], 0.05, 1000, precision=precision)
    sim.set_wall_position("z+", 0.8)
    assert sim.walls().position[5] == 0.8
    sim.set_wall_control(5, sphere.WallControl(mode="velocity", velocity=0.1))
    sim.run(100)
    walls = sim.walls()
    assert walls.mode[5] == "velocity" and sim.settings.walls[5].velocity == pytest.approx(0.1, rel=eps(precision))
    # Walls move in double whatever the precision: 100 steps of 0.1 m/s inwards.
    velocity = float(np.float32(0.1)) if precision == "float" else 0.1
    assert walls.position[5] == pytest.approx(0.8 - 100 * velocity * sim.dt, abs=1e-14)
    assert walls.velocity[5] == -velocity


def test_python_built_run_restarts_bit_identically(precision, tmp_path):
    sim, _ = collision(precision, 0.5)
    sim.run(600)
    sim.write_checkpoint(tmp_path / "a.ck")
    sim.run(1000)
    again = sphere.read_checkpoint(tmp_path / "a.ck")
    assert again.precision == precision
    again.run(1000)
    np.testing.assert_array_equal(again.snapshot().velocities, sim.snapshot().velocities)
    np.testing.assert_array_equal(again.snapshot().positions, sim.snapshot().positions)
