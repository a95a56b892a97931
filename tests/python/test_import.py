"""The package imports, says the project's version and has both precisions."""

import os
import re

import sphere
from conftest import linear_settings


def test_version_is_the_projects():
    with open(os.path.join(os.environ["SPHERE_SOURCE_DIR"], "CMakeLists.txt")) as f:
        version = re.search(r"project\(sphere\s+VERSION\s+([0-9.]+)", f.read()).group(1)
    assert sphere.__version__ == version


def test_error_is_a_runtime_error():
    assert issubclass(sphere.Error, RuntimeError)


def test_both_precisions():
    assert sphere.PRECISIONS == ("float", "double")
    for precision in sphere.PRECISIONS:
        sim = sphere.Simulation(linear_settings(), [[0.5, 0.5, 0.5]], 0.1, 1000, precision=precision)
        assert sim.precision == precision
        assert len(sim) == 1
