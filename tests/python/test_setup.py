"""The set-up helpers: radii, lattices, random packings, the fitted world and deposition."""

import numpy as np
import pytest

import sphere
from conftest import eps


def test_uniform_radii(precision):
    r = sphere.uniform_radii(1000, 0.009, 0.011, 7, precision=precision)
    assert r.shape == (1000,) and r.dtype == (np.float32 if precision == "float" else np.float64)
    assert r.min() >= np.float32(0.009) if precision == "float" else r.min() >= 0.009
    assert r.max() <= 0.011 and r.max() - r.min() > 0.0019
    np.testing.assert_array_equal(r, sphere.uniform_radii(1000, 0.009, 0.011, 7, precision=precision))
    assert not np.array_equal(r, sphere.uniform_radii(1000, 0.009, 0.011, 8, precision=precision))
    assert sphere.lognormal_radii(2000, 0.01, 0.001, 1, precision=precision).mean() == pytest.approx(0.01, rel=0.01)
    bimodal = sphere.bimodal_radii(100, 0.01, 0.02, 1.0, 1, precision=precision)
    assert (bimodal == bimodal.max()).sum() == round(100 / 9)  # equal volumes: 1 / (1 + 8) large ones


def test_random_packing_does_not_overlap(precision):
    radii = sphere.uniform_radii(300, 0.008, 0.012, 1, precision=precision)
    s = sphere.Settings(hi=(0.2, 0.2, 0.3), boundary=("periodic", "wall", "wall"))
    gap = 0.001
    x = sphere.random_packing(radii, s, 2, gap=gap, precision=precision).astype(np.float64)
    r = radii.astype(np.float64)
    assert x.shape == (300, 3)
    d = x[:, None, :] - x[None, :, :]
    d[..., 0] -= 0.2 * np.round(d[..., 0] / 0.2)  # nearest image on the periodic x axis
    distance = np.sqrt((d**2).sum(-1)) + np.eye(300)
    assert (distance - r[:, None] - r[None, :] >= gap * (1 - 1e-6) - 1e-6 * np.eye(300)).all()
    assert (x[:, 0] >= 0).all() and (x[:, 0] < 0.2).all()
    for a, hi in ((1, 0.2), (2, 0.3)):
        assert (x[:, a] - r >= 0).all() and (x[:, a] + r <= hi).all()
    with pytest.raises(sphere.Error, match="random_packing: could not place particle"):
        sphere.random_packing(np.full(100, 0.05), s, 1, max_tries=100, precision=precision)


def test_lattices(precision):
    x = sphere.cubic_lattice((3, 2, 4), 0.02, origin=(1.0, 0.0, -0.5), precision=precision)
    assert x.shape == (24, 3) and x.dtype == (np.float32 if precision == "float" else np.float64)
    # Particle i + nx (j + ny k) at origin + ((i, j, k) + 1/2) s.
    i, j, k = np.arange(24) % 3, np.arange(24) // 3 % 2, np.arange(24) // 6
    expected = np.array([1.0, 0.0, -0.5]) + (np.column_stack([i, j, k]) + 0.5) * 0.02
    assert np.allclose(x, expected, rtol=0, atol=4 * eps(precision))
    stretched = sphere.cubic_lattice((2, 2, 2), (0.01, 0.02, 0.03), precision=precision)
    assert np.allclose(stretched.max(axis=0), [0.015, 0.03, 0.045], rtol=eps(precision))
    jittered = sphere.jittered_lattice((3, 2, 4), 0.02, 0.002, 5, origin=(1.0, 0.0, -0.5), precision=precision)
    offset = jittered.astype(np.float64) - x.astype(np.float64)
    assert np.abs(offset).max() <= 0.002 * (1 + 1e-6) and np.abs(offset).max() > 0.0015
    assert abs(offset.mean()) < 0.0005  # uniform in [-jitter, jitter]
    np.testing.assert_array_equal(jittered, sphere.jittered_lattice((3, 2, 4), 0.02, 0.002, 5, origin=(1.0, 0.0, -0.5),
                                                                    precision=precision))
    with pytest.raises(sphere.Error, match="cubic_lattice: spacing"):
        sphere.cubic_lattice((2, 2, 2), -0.01, precision=precision)
    with pytest.raises(sphere.Error, match="jittered_lattice: jitter = -0.001[0-9]* m must be non-negative"):
        sphere.jittered_lattice((2, 2, 2), 0.01, -0.001, 1, precision=precision)


def test_fit_world(precision):
    x = np.array([[0.1, 0.2, 0.3], [0.4, 0.1, 0.35]])
    r = np.array([0.01, 0.02])
    s = sphere.Settings(skin=0.001, cell_size=0.5)
    sphere.fit_world(s, x, r, margin=1.0, headroom=0.1, precision=precision)
    tol = 4 * eps(precision)
    np.testing.assert_allclose(s.lo, (x - r[:, None]).min(0) - 0.02, atol=tol)
    cell = 2 * 0.02 + 0.001
    for a in range(3):
        top = (x[:, a] + r).max() + 0.02 + (0.1 if a == 2 else 0)
        assert top <= s.hi[a] + tol < top + cell + tol  # whole cells upwards
    assert s.cell_size == 0


def test_deposit(precision):
    sim = sphere.deposited_sample(particles=60, precision=precision)
    assert sim.energy().kinetic < 1e-4 * 60 * sim.snapshot().masses.mean() * 9.81 * 0.02
    assert sim.walls().position[5] == sphere.sample_top(sim)
    assert sim.time > 0.1  # at least the time to fall through the world
