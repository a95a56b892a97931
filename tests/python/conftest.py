"""Shared by the tests of the Python package sphere. tests/python_tests.cmake runs each test file
with /usr/bin/python3 -m pytest, PYTHONPATH at the build's package folder (build/python),
OMP_NUM_THREADS=1, SPHERE_SOURCE_DIR at the repository, SPHERE_CONSOLIDATION, SPHERE_SHEAR,
SPHERE_UNIAXIAL and SPHERE_TRIAXIAL at the C++ examples and SPHERE_PROGRAM at the sphere program
(each unset when it is not built: the tests that run it are skipped then)."""

import os
import subprocess

import numpy as np
import pytest

import sphere


@pytest.fixture(params=sphere.PRECISIONS)
def precision(request):
    """Each test that takes it runs in float and in double."""
    return request.param


def eps(precision):
    """The machine epsilon of a precision."""
    return float(np.finfo(np.float32 if precision == "float" else np.float64).eps)


def linear_settings(lo=(0.0, 0.0, 0.0), hi=(1.0, 1.0, 1.0), k_n=1e5, **kw):
    """Settings with the linear law, k_t = k_n, no damping or friction, for pairs and walls."""
    return sphere.Settings(lo=lo, hi=hi, contact=sphere.ContactParams(k_n=k_n, k_t=k_n),
                           wall=sphere.ContactParams(k_n=k_n, k_t=k_n), **kw)


@pytest.fixture(scope="session")
def cpp_consolidation(tmp_path_factory):
    """run(precision, duration): the C++ consolidation example on 150 particles, loaded for
    `duration` s (once per arguments); returns its checkpoint's path and its standard output."""
    program = os.environ.get("SPHERE_CONSOLIDATION")
    if not program:
        pytest.skip("SPHERE_CONSOLIDATION is not set: the C++ consolidation example is not built")
    runs = {}

    def run(precision, duration):
        if (precision, duration) not in runs:
            out = tmp_path_factory.mktemp(f"consolidation-{precision}")
            done = subprocess.run([program, "-n", "150", "--time", str(duration), "--precision", precision, "-q",
                                   "-o", str(out)], capture_output=True, text=True, check=True)
            runs[precision, duration] = (out / "checkpoint.ck", done.stdout)
        return runs[precision, duration]

    return run


def cpp_program(variable, what):
    """The path in environment variable `variable`; skips the test when it is unset."""
    program = os.environ.get(variable)
    if not program:
        pytest.skip(f"{variable} is not set: {what} is not built")
    return program


def run_example(program, out, *options):
    """Runs a C++ example quietly into folder `out` with `options`; returns its standard output
    without the last line ('output in <folder>: ...', which names the folder)."""
    done = subprocess.run([program, *map(str, options), "-q", "-o", str(out)], capture_output=True, text=True,
                          check=True)
    return [line for line in done.stdout.splitlines() if not line.startswith("output in")]
