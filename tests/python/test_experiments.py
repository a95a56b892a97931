"""sphere.uniaxial and sphere.triaxial against the C++ uniaxial and triaxial examples (run with -q):
the same printed lines, the same final checkpoint and the same series.csv columns, to the last
bit; from a fresh sample and from a saved one (sample= against --sample). 150 particles, phases
of 0.01 s, rows every 0.005 s; float and double."""

import csv

import numpy as np
import pytest
from conftest import cpp_program, run_example

import sphere


def csv_columns(path):
    """The columns of a series.csv as float arrays by name (written with 17 significant digits:
    read back exactly)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {name: np.array([float(row[name]) for row in rows]) for name in rows[0]}


UNIAXIAL = ["-n", 150, "--time", 0.01, "--output-interval", 0.005]
TRIAXIAL = ["-n", 150, "--confine-time", 0.01, "--time", 0.01, "--output-interval", 0.005]


def test_uniaxial_equals_the_cpp_example(precision, tmp_path, capsys):
    program = cpp_program("SPHERE_UNIAXIAL", "the C++ uniaxial example")
    expected = run_example(program, tmp_path / "cpp", *UNIAXIAL, "--precision", precision)
    result = sphere.uniaxial(particles=150, duration=0.01, output_interval=0.005, precision=precision,
                             checkpoint=tmp_path / "py.ck")
    assert capsys.readouterr().out.splitlines() == expected
    assert (tmp_path / "py.ck").read_bytes() == (tmp_path / "cpp" / "checkpoint.ck").read_bytes()

    cpp = csv_columns(tmp_path / "cpp" / "series.csv")
    s = result.series
    assert len(s.time) == len(cpp["time_s"]) >= 2  # at the start, then at multiples of the interval's steps
    for name, column in [("time", "time_s"), ("axial_strain", "axial_strain"), ("axial_stress", "normal_stress_Pa"),
                         ("porosity", "porosity"), ("void_ratio", "void_ratio")]:
        assert np.array_equal(getattr(s, name), cpp[column]), name
    # The result is what was printed, and the wall moved down at 0.05 m/s.
    assert f"{result.axial_strain:14.6f}" in expected[1]
    assert f"{result.axial_stress:14.1f}" in expected[2]
    assert s.axial_strain[0] == 0.0
    descent, dt = result.axial_strain * result.height, result.simulation.dt
    assert descent == pytest.approx(0.05 * round(0.01 / dt) * dt, rel=1e-3 if precision == "float" else 1e-9)
    assert result.simulation.walls().mode[5] == "velocity"


def test_triaxial_equals_the_cpp_example(precision, tmp_path, capsys):
    program = cpp_program("SPHERE_TRIAXIAL", "the C++ triaxial example")
    expected = run_example(program, tmp_path / "cpp", *TRIAXIAL, "--precision", precision)
    result = sphere.triaxial(particles=150, confine_duration=0.01, duration=0.01, output_interval=0.005,
                             precision=precision, checkpoint=tmp_path / "py.ck")
    assert capsys.readouterr().out.splitlines() == expected
    assert (tmp_path / "py.ck").read_bytes() == (tmp_path / "cpp" / "checkpoint.ck").read_bytes()

    cpp = csv_columns(tmp_path / "cpp" / "series.csv")
    s = result.series
    assert len(s.time) == len(cpp["time_s"]) >= 4  # about every 0.005 s over 0.02 s
    assert np.array_equal(s.time, cpp["time_s"])
    assert np.array_equal(s.axial_stress, cpp["normal_stress_Pa"])
    assert np.array_equal(s.lateral_stress, cpp["side_stress_Pa"])
    assert np.array_equal(s.porosity, cpp["porosity"])
    assert np.array_equal(s.void_ratio, cpp["void_ratio"])
    # The q-p path from the stresses; strains only in the axial compression (the CSV's rows of the
    # isotropic phase hold them against unset references).
    assert np.array_equal(s.deviatoric_stress, cpp["normal_stress_Pa"] - cpp["side_stress_Pa"])
    assert np.array_equal(s.mean_stress, (cpp["normal_stress_Pa"] + 2 * cpp["side_stress_Pa"]) / 3)
    flags = s.axial.tolist()
    assert flags == sorted(flags) and flags[0] is False and flags[-1] is True  # the isotropic rows first
    assert np.all(s.time[s.axial] > s.time[0] + 0.009)
    assert np.all(np.isnan(s.axial_strain[~s.axial])) and np.all(np.isnan(s.volumetric_strain[~s.axial]))
    assert np.array_equal(s.axial_strain[s.axial], cpp["axial_strain"][s.axial])
    assert np.array_equal(s.volumetric_strain[s.axial], cpp["volumetric_strain"][s.axial])
    # The result is what was printed; the side walls are walls, held at the confining stress.
    assert f"{result.deviatoric_stress:14.1f}" in expected[-3]
    assert f"{result.stress_ratio:14.4f}" in expected[-2]
    assert result.deviatoric_stress == result.axial_stress - result.lateral_stress
    walls = result.simulation.walls()
    assert walls.active.tolist() == [True] * 6
    assert walls.mode[:4] == ["stress"] * 4 and walls.mode[5] == "velocity"


def test_saved_samples_equal_the_cpp_examples(precision, tmp_path, capsys):
    """uniaxial --sample (a consolidation's checkpoint) and triaxial --sample (a triaxial's)."""
    uniaxial = cpp_program("SPHERE_UNIAXIAL", "the C++ uniaxial example")
    triaxial = cpp_program("SPHERE_TRIAXIAL", "the C++ triaxial example")
    consolidation = cpp_program("SPHERE_CONSOLIDATION", "the C++ consolidation example")
    p = ["--precision", precision]
    run_example(consolidation, tmp_path / "c0", "-n", 150, "--time", 0.01, *p)
    run_example(triaxial, tmp_path / "t0", *TRIAXIAL, *p)
    periodic, walled = tmp_path / "c0" / "checkpoint.ck", tmp_path / "t0" / "checkpoint.ck"
    first = run_example(uniaxial, tmp_path / "u1", "--sample", periodic, "--time", 0.01, "--velocity", 0.1, *p)
    second = run_example(triaxial, tmp_path / "t1", "--sample", walled, "--confine-time", 0.005, "--time", 0.01,
                         "--confining", 2e4, *p)

    sphere.uniaxial(sample=periodic, duration=0.01, velocity=0.1, precision=precision, checkpoint=tmp_path / "u.ck")
    sphere.triaxial(sample=walled, confine_duration=0.005, duration=0.01, confining=2e4, precision=precision,
                    checkpoint=tmp_path / "t.ck")
    assert capsys.readouterr().out.splitlines() == first + second
    assert first[0].startswith("sample: 150 particles from ")
    assert (tmp_path / "u.ck").read_bytes() == (tmp_path / "u1" / "checkpoint.ck").read_bytes()
    assert (tmp_path / "t.ck").read_bytes() == (tmp_path / "t1" / "checkpoint.ck").read_bytes()

    # Each refuses the other's kind of sample.
    with pytest.raises(sphere.Error, match="closed by walls on x and y"):
        sphere.triaxial(sample=periodic, precision=precision, verbose=False)
    with pytest.raises(sphere.Error, match="periodic on x and y"):
        sphere.uniaxial(sample=walled, precision=precision, verbose=False)


def test_uniaxial_refuses_more_than_half_the_height(tmp_path):
    sample = tmp_path / "sample.ck"
    sphere.consolidate(particles=150, duration=0.001, checkpoint=sample, verbose=False)
    with pytest.raises(sphere.Error, match=r"^sphere: velocity=1 m/s for duration=1 s would compress the sample by "
                                           r"\d+(\.\d+)?% of its height; at most 50% is allowed$"):
        sphere.uniaxial(sample=sample, velocity=1.0, duration=1.0, verbose=False)
