"""sphere.plot: every figure is written as a PNG that matplotlib reads back, with the size
asked for; the Recorder's series; wrong arguments by message."""

import numpy as np
import pytest
from conftest import linear_settings

import sphere

matplotlib = pytest.importorskip("matplotlib", reason="sphere.plot needs matplotlib (python3-matplotlib)")
import matplotlib.image  # noqa: E402

import sphere.plot  # noqa: E402


@pytest.fixture(scope="module")
def loaded():
    """A few particles dropped on the floor under an upper wall pushed down at 1 kPa, recorded
    every 50 steps for 0.05 s."""
    s = linear_settings(hi=(0.1, 0.1, 0.2), boundary=("periodic", "periodic", "wall"), gravity=(0, 0, -9.81))
    s.walls[5] = sphere.WallControl(mode="stress", stress=1e3, mass=0.1)
    positions = [[0.02 + 0.03 * (k % 3), 0.02 + 0.03 * (k // 3 % 3), 0.02 + 0.025 * (k // 9)] for k in range(27)]
    sim = sphere.Simulation(s, positions, 0.01, 2500)
    sim.set_wall_position("z+", 0.1)
    recorder = sphere.Recorder(sim, every=50)
    sim.run_for(0.05)
    return sim, recorder


def written(path, figure):
    """Reads the PNG back: its pixel size is the figure's (inches times 100 dpi)."""
    image = matplotlib.image.imread(path)
    width, height = figure.get_size_inches() * 100
    assert image.shape[:2] == (round(height), round(width))
    assert image.std() > 0  # something is drawn
    return image


def test_recorder(loaded):
    sim, rec = loaded
    steps = sim.steps
    assert len(rec) == steps // 50 + 1  # once at the start, then every 50 steps
    assert rec.time[0] == 0 and rec.time[-1] == pytest.approx((steps - steps % 50) * sim.dt, rel=1e-12)
    assert rec.wall_position.shape == (len(rec), 6)
    assert rec.wall_position[0, 5] == 0.1 and rec.wall_position[-1, 5] < 0.1  # the wall moved down
    assert np.isnan(rec.wall_stress[:, :4]).all() and not np.isnan(rec.wall_stress[:, 4:]).any()
    assert rec.energy["kinetic"][0] == 0 and rec.energy["kinetic"][-1] > 0
    assert set(rec.energy) >= {"kinetic", "potential", "total"}


def test_figures_are_written(loaded, tmp_path):
    sim, rec = loaded
    sim.run(1)
    figures = {
        "energy.png": sphere.plot.energy(rec, tmp_path / "energy.png"),
        "energy_now.png": sphere.plot.energy(sim, tmp_path / "energy_now.png"),
        "walls.png": sphere.plot.walls(rec, tmp_path / "walls.png"),
        "rose.png": sphere.plot.rose(sim, tmp_path / "rose.png"),
        "profile.png": sphere.plot.porosity_profile(sim, tmp_path / "profile.png", slices=5),
        "rose_given.png": sphere.plot.rose(sphere.rose([10, 100, 200], [5, 45, 80]), tmp_path / "rose_given.png"),
    }
    series = sphere.ShearSeries(*(np.linspace(0, 1, 5) + k for k in range(8)))
    figures["shear.png"] = sphere.plot.shear(series, tmp_path / "shear.png")
    for name, fig in figures.items():
        written(tmp_path / name, fig)
    assert sphere.plot.energy(rec) is not None  # without a path: the figure only
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(figures)


def test_wrong_arguments(loaded):
    sim, _ = loaded
    with pytest.raises(sphere.Error, match=r"plot.walls: Simulation given; a sphere.Recorder is needed"):
        sphere.plot.walls(sim)
    with pytest.raises(sphere.Error, match=r"plot.shear: list given"):
        sphere.plot.shear([1, 2])
    with pytest.raises(sphere.Error, match=r"plot.energy: dict given"):
        sphere.plot.energy({})


def triaxial_series():
    """A made-up stress path: three isotropic rows at q = 0, then q growing with the strain."""
    axial = np.array([False, False, False, True, True, True])
    strain = np.where(axial, [0, 0, 0, 0.01, 0.02, 0.03], np.nan)
    sigma_3 = np.full(6, 1e4)
    sigma_1 = np.array([0.5e4, 0.9e4, 1e4, 1.5e4, 2e4, 2.4e4])
    q, p = sigma_1 - sigma_3, (sigma_1 + 2 * sigma_3) / 3
    return sphere.TriaxialSeries(np.linspace(0, 0.05, 6), axial, strain, strain / 2, sigma_1, sigma_3, q, p,
                                 np.full(6, 0.4), np.full(6, 0.4 / 0.6))


def test_triaxial_and_uniaxial_figures(tmp_path):
    series = triaxial_series()
    fig = sphere.plot.triaxial(series, tmp_path / "triaxial.png")
    written(tmp_path / "triaxial.png", fig)
    path_ax, ratio_ax = fig.axes
    iso, axial = path_ax.lines
    assert np.array_equal(iso.get_xdata(), series.mean_stress[:3])
    assert np.array_equal(iso.get_ydata(), series.deviatoric_stress[:3])
    assert np.array_equal(axial.get_xdata(), series.mean_stress[3:])
    assert np.array_equal(ratio_ax.lines[0].get_xdata(), [0.01, 0.02, 0.03])
    assert np.array_equal(ratio_ax.lines[0].get_ydata(), series.deviatoric_stress[3:] / series.mean_stress[3:])
    assert path_ax.get_xlabel() == "mean stress p (Pa)" and ratio_ax.get_ylabel() == "q / p"

    u = sphere.UniaxialSeries(*(np.linspace(0, 1, 4) + k for k in range(5)))
    written(tmp_path / "uniaxial.png", sphere.plot.uniaxial(u, tmp_path / "uniaxial.png"))
    with pytest.raises(sphere.Error, match=r"plot.triaxial: UniaxialSeries given; a sphere.Triaxial or "
                                           r"sphere.TriaxialSeries is needed"):
        sphere.plot.triaxial(u)
