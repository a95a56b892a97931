"""The analyses against hand-computed values on tiny configurations: three fixed particles in
contact with known overlaps (forces k_n * overlap, coordination numbers, the Love-Weber tensor
from its definition, the contact rose), a particle pressed on a wall (its stress), one sphere
in a box (porosity and its profile), and the shear tracker of a driven layer."""

import math

import numpy as np
import pytest
from conftest import linear_settings

import sphere

K_N, R = 1e5, 0.01
D1, D2 = 1e-4, 2e-4  # overlaps (m) of the pairs 0-1 (along x) and 1-2 (along z)


def triplet(precision, **settings):
    """Particles 0 and 1 along x overlapping by D1, particle 2 above 1 overlapping it by D2; all
    fixed (nothing moves: the positions after the step are those the forces were computed
    from), far from the walls of a box of side 0.2 m; one step taken."""
    s = linear_settings(lo=(-0.1, -0.1, -0.1), hi=(0.1, 0.1, 0.1), k_n=K_N, **settings)
    positions = [[-2 * R + D1, 0, 0], [0, 0, 0], [0, 0, 2 * R - D2]]
    sim = sphere.Simulation(s, positions, R, 2500, fixed=[True] * 3, precision=precision)
    sim.run(1)
    return sim


def rounded(x, precision):
    """x rounded to the precision (as the library stores a setting or a radius)."""
    return float(np.float32(x)) if precision == "float" else x


def tolerance(precision):
    """Relative error of values computed from overlaps of positions in the precision: the
    overlaps are differences of numbers of size R, 1e-2 of them: 100 ulp of R."""
    return 1e-3 if precision == "float" else 1e-10


def test_force_chains_and_coordination(precision):
    sim = triplet(precision)
    chains = sphere.force_chains(sim)
    assert len(chains) == 2
    assert chains.i.tolist() == [0, 1] and chains.j.tolist() == [1, 2]
    tol = tolerance(precision)
    assert chains.normal == pytest.approx([K_N * D1, K_N * D2], rel=tol)
    np.testing.assert_array_equal(chains.tangential, np.zeros((2, 3)))
    assert chains.branch[0] == pytest.approx([2 * R - D1, 0, 0], rel=tol)
    assert chains.branch[1] == pytest.approx([0, 0, 2 * R - D2], rel=tol)
    np.testing.assert_array_equal(chains.x_i[1], sim.snapshot().positions[1])
    assert sphere.contact_counts(sim).tolist() == [1, 2, 1]
    assert sphere.coordination(sim) == 4 / 3  # 2 pairs * 2 / 3 particles, exactly


def test_stress_tensor_from_its_definition(precision):
    sim = triplet(precision)
    volume = (2 * rounded(0.1, precision)) ** 3  # the walls at the box's faces, +-0.1 m in the precision
    assert sphere.volume_between_walls(sim) == pytest.approx(volume, rel=1e-15)
    # sigma_ij = -(1/V) sum over both sides of each pair of f_i l_j: for a pair at distance d
    # along an axis with normal force k_n delta (repulsive), sigma_aa = k_n delta d / V.
    expected = np.zeros((3, 3))
    expected[0, 0] = K_N * D1 * (2 * R - D1) / volume
    expected[2, 2] = K_N * D2 * (2 * R - D2) / volume
    sigma = sphere.stress_tensor(sim)
    assert sigma.shape == (3, 3)
    np.testing.assert_allclose(sigma, expected, rtol=tolerance(precision), atol=0)
    np.testing.assert_allclose(sphere.stress_tensor(sim, volume=1.0), expected * volume, rtol=tolerance(precision))


def test_contact_rose_and_orientations(precision):
    sim = triplet(precision)
    r = sphere.contact_rose(sim, trend_bins=4, plunge_bins=3)
    # The x pair: trend 90 (east), plunge 0; the z pair: plunge 90 (its trend, undefined, is 180
    # by the library's convention: atan2(-0, -0) of the downward axis).
    assert r.trend.tolist() == [0, 1, 1, 0]
    assert r.plunge.tolist() == [1, 0, 1]
    assert r.trend_edges.tolist() == [0, 90, 180, 270, 360]
    trend, plunge = sphere.orientations([[1, 0, 0], [0, 1, -1], [-1, 0, 0], [0, -1, 1], [1, 1, -math.sqrt(2)]])
    np.testing.assert_allclose(trend, [90, 0, 90, 0, 45], atol=1e-12)
    np.testing.assert_allclose(plunge, [0, 45, 0, 45, 45], atol=1e-12)
    assert sphere.rose([], [], 36, 9).trend.sum() == 0
    with pytest.raises(sphere.Error, match="each must be at least 1"):
        sphere.rose([10], [10], 0, 9)


def test_wall_stresses(precision):
    # A fixed particle pressed 2e-4 m into the floor of a box of 0.2 x 0.2 m.
    s = linear_settings(lo=(-0.1, -0.1, -0.1), hi=(0.1, 0.1, 0.1), k_n=K_N, boundary=("periodic", "wall", "wall"))
    sim = sphere.Simulation(s, [[0, 0, -0.1 + R - D2]], R, 2500, fixed=[True], precision=precision)
    sim.run(1)
    stresses = sphere.wall_stresses(sim)
    assert np.isnan(stresses[:2]).all()
    side = 2 * rounded(0.1, precision)
    assert stresses[4] == pytest.approx(K_N * D2 / side**2, rel=tolerance(precision))
    assert stresses[[2, 3, 5]].tolist() == [0, 0, 0]
    assert sphere.contact_counts(sim, with_walls=True).tolist() == [1]
    assert sphere.coordination(sim) == 0 and sphere.coordination(sim, with_walls=True) == 1
    # The wall contact's branch vector reaches the floor: sigma_zz = k_n delta (R - delta) / V.
    sigma = sphere.stress_tensor(sim)
    assert sigma[2, 2] == pytest.approx(K_N * D2 * (R - D2) / side**3, rel=tolerance(precision))


def test_porosity_and_profile(precision):
    # One sphere of radius 0.1 m centred in a unit box: 2 slices split it in halves.
    s = linear_settings()
    sim = sphere.Simulation(s, [[0.5, 0.5, 0.5]], 0.1, 2500, precision=precision)
    r = rounded(0.1, precision)
    ball = 4 / 3 * math.pi * r**3
    assert sphere.porosity(sim)["porosity"] == pytest.approx(1 - ball, rel=1e-12)
    p = sphere.porosity_profile(sim, 2)
    assert p.z_lo.tolist() == [0, 0.5] and p.z_hi.tolist() == [0.5, 1] and p.z.tolist() == [0.25, 0.75]
    np.testing.assert_allclose(p.porosity, [1 - ball / 2 / 0.5] * 2, rtol=1e-12)
    # A box around the upper half of the sphere only.
    q = sphere.porosity(sim, lo=(0.3, 0.3, 0.5), hi=(0.7, 0.7, 0.5 + r))
    assert q["solid_volume"] == pytest.approx(ball / 2, rel=1e-12)
    assert q["volume"] == pytest.approx(0.4 * 0.4 * r, rel=1e-12)
    assert q["void_ratio"] == pytest.approx(sphere.void_ratio(q["porosity"]), rel=1e-12)
    # Ten slices: the sphere's volume is conserved.
    p10 = sphere.porosity_profile(sim, 10, lo=(0, 0, 0), hi=(1, 1, 1))
    assert np.sum((1 - p10.porosity) * 0.1) == pytest.approx(ball, rel=1e-12)
    with pytest.raises(sphere.Error, match="slices = 0"):
        sphere.porosity_profile(sim, 0)
    with pytest.raises(sphere.Error, match="give both lo and hi"):
        sphere.porosity(sim, lo=(0, 0, 0))


def test_contact_analyses_need_the_forces():
    sim = triplet("double", contact_forces=False)
    with pytest.raises(sphere.Error, match="contact analyses need the contact forces"):
        sphere.force_chains(sim)


def test_shear_tracker():
    # A fixed floor particle and a prescribed one 0.05 m above it, moved along x at 1 m/s in a
    # world periodic in x, across the period: strain = 1 m/s t / 0.05 m.
    s = linear_settings(boundary=("periodic", "wall", "wall"))
    sim = sphere.Simulation(s, [[0.5, 0.5, 0.2], [0.5, 0.5, 0.25]], 0.01, 2500, velocities=[[0, 0, 0], [1.0, 0, 0]],
                            kinds=["fixed", "prescribed"])
    tracker = sphere.ShearTracker(sim)
    assert tracker.layers == {"top": [1], "bottom": [0]}
    assert tracker.velocity == pytest.approx(1.0, rel=1e-15) and tracker.height == pytest.approx(0.05, rel=1e-14)
    while sim.time < 0.7:  # 0.7 m: the top particle wraps around once at x = 1
        sim.run(1000)
        tracker.update()
    assert sim.snapshot().positions[1, 0] < 0.5
    assert tracker.displacement == pytest.approx(sim.time, rel=1e-9)
    assert tracker.strain == pytest.approx(sim.time / 0.05, rel=1e-9)
    assert tracker.strain_rate == pytest.approx(20, rel=1e-12)
    s2 = linear_settings()
    with pytest.raises(sphere.Error, match="a shear experiment needs both"):
        sphere.ShearTracker(sphere.Simulation(s2, [[0.5, 0.5, 0.5]], 0.01, 2500))
