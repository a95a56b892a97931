"""sphere.shear against the C++ shear example, and consolidate/shear started from a saved sample
(sample=) against the examples run with --sample: the same printed lines, the same final
checkpoint and the same series, to the last bit. 150 particles, 0.01 s of consolidation, a
shear strain of 0.01 (0.04 s), rows every 0.005 s; float and double."""

import csv

import numpy as np
import pytest
from conftest import cpp_program, run_example

import sphere

SMALL = dict(particles=150, consolidation_time=0.01, strain=0.01, output_interval=0.005)
OPTIONS = ["-n", 150, "--consolidation-time", 0.01, "--strain", 0.01, "--output-interval", 0.005]
SERIES = ["time_s", "shear_strain", "shear_stress_Pa", "normal_stress_Pa", "friction_coefficient", "dilation_m",
          "porosity", "void_ratio"]


def series_rows(path, count):
    """The last `count` rows of a series.csv, the ShearSeries' columns, as floats (written with 17
    significant digits: read back exactly)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return np.array([[float(row[c]) for c in SERIES] for row in rows[-count:]]).T


def test_shear_equals_the_cpp_example(precision, tmp_path, capsys):
    program = cpp_program("SPHERE_SHEAR", "the C++ shear example")
    expected = run_example(program, tmp_path / "cpp", *OPTIONS, "--precision", precision)
    result = sphere.shear(**SMALL, precision=precision, checkpoint=tmp_path / "py.ck")
    assert capsys.readouterr().out.splitlines() == expected
    assert (tmp_path / "py.ck").read_bytes() == (tmp_path / "cpp" / "checkpoint.ck").read_bytes()

    # The series: 8 rows in 0.04 s of shear, each equal to the CSV's row.
    s = result.series
    assert len(s.time) == 8
    cpp = series_rows(tmp_path / "cpp" / "series.csv", len(s.time))
    for k, name in enumerate(["time", "strain", "shear_stress", "normal_stress", "friction", "dilation", "porosity",
                              "void_ratio"]):
        assert np.array_equal(getattr(s, name), cpp[k]), name
    # The result's fields are the printed ones, and consistent with the simulation.
    assert f"{result.strain:14.6f}" in expected[2]
    assert f"{result.drive_work:14.6e}" in expected[5]
    assert result.simulation.energy().dissipated_friction == result.frictional_dissipation
    assert len(result.fixed) == 47 if precision == "double" else len(result.fixed) > 0
    kinds = result.simulation.snapshot().kinds
    assert set(kinds[result.fixed]) == {sphere.MOTION_KINDS.index("fixed")}
    assert set(kinds[result.driven]) == {sphere.MOTION_KINDS.index("prescribed_horizontal")}
    assert result.velocity == 0.25 * result.height
    # The strain grows with the run: 0.01 +- 20% (the layers are not rigid).
    assert 0.008 < result.strain < 0.012
    assert np.all(np.diff(s.strain) > 0)


def test_chain_from_a_saved_sample_equals_the_cpp_chain(precision, tmp_path, capsys):
    """consolidation -> consolidation --sample -> shear --sample, in C++ and in Python."""
    consolidation = cpp_program("SPHERE_CONSOLIDATION", "the C++ consolidation example")
    shear = cpp_program("SPHERE_SHEAR", "the C++ shear example")
    p = ["--precision", precision]
    first = run_example(consolidation, tmp_path / "c1", "-n", 150, "--time", 0.01, *p)
    sample = tmp_path / "c1" / "checkpoint.ck"
    second = run_example(consolidation, tmp_path / "c2", "--sample", sample, "--time", 0.01, "--stress", 2e4, *p)
    third = run_example(shear, tmp_path / "c3", "--sample", tmp_path / "c2" / "checkpoint.ck",
                        "--consolidation-time", 0.005, "--strain", 0.005, *p)

    sphere.consolidate(particles=150, duration=0.01, precision=precision, checkpoint=tmp_path / "p1.ck")
    sphere.consolidate(sample=tmp_path / "p1.ck", duration=0.01, stress=2e4, precision=precision,
                       checkpoint=tmp_path / "p2.ck")
    result = sphere.shear(sample=tmp_path / "p2.ck", consolidation_time=0.005, strain=0.005, precision=precision,
                          checkpoint=tmp_path / "p3.ck")
    printed = capsys.readouterr().out.replace(str(tmp_path / "p1.ck"), str(sample))
    printed = printed.replace(str(tmp_path / "p2.ck"), str(tmp_path / "c2" / "checkpoint.ck"))
    assert printed.splitlines() == first + second + third
    assert second[0].startswith("sample: 150 particles from ")
    for k in (1, 2, 3):
        assert (tmp_path / f"p{k}.ck").read_bytes() == (tmp_path / f"c{k}" / "checkpoint.ck").read_bytes(), k
    assert result.simulation.size == 150


def test_saved_sample_checks(tmp_path):
    with pytest.raises(sphere.Error, match="cannot|missing|open|exist"):
        sphere.shear(sample=tmp_path / "none.ck", verbose=False)
    s = sphere.Settings(hi=(0.1, 0.1, 0.1))
    s.contact = s.wall = sphere.ContactParams(k_n=1e5, k_t=1e5)
    sim = sphere.Simulation(s, [[0.05, 0.05, 0.05]], 0.01, 2500)
    sim.write_checkpoint(tmp_path / "walled.ck")
    with pytest.raises(sphere.Error, match="periodic on x and y"):
        sphere.consolidate(sample=tmp_path / "walled.ck", verbose=False)
