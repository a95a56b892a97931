"""Builds the Python package sphere with the project's CMake (python/CMakeLists.txt): `pip install .`
configures the project in a build folder with only the package switched on, builds the extension
module sphere._sphere (target sphere_python) and installs it with the package's Python files
(python/sphere/). CMAKE_ARGS adds CMake options, e.g. CMAKE_ARGS=-DSPHERE_NATIVE=ON for code
tuned to this machine's CPU (off by default: a wheel may run elsewhere). Needs cmake, a C++17
compiler, OpenMP, the Thrust headers and pybind11; libpng's development files (Debian's
libpng-dev) when found give the pictures (Simulation.render: the module then links libpng),
without them the package builds without pictures (docs/python.md)."""

import os
import re
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def project_version():
    """The version in the top-level CMakeLists.txt's project()."""
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(sphere\s+VERSION\s+([0-9.]+)", text).group(1)


class CMakeBuild(build_ext):
    """Builds the extension module with CMake instead of setuptools' compiler calls."""

    def build_extension(self, ext):
        import pybind11

        build = Path(self.build_temp).resolve() / "cmake"
        subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                        "-DSPHERE_BUILD_TESTS=OFF", "-DSPHERE_BUILD_EXAMPLES=OFF", "-DSPHERE_BUILD_BENCH=OFF",
                        "-DSPHERE_ENABLE_CUDA=OFF", "-DSPHERE_NATIVE=OFF", "-DSPHERE_BUILD_PYTHON=ON",
                        f"-DSPHERE_PYTHON={sys.executable}", f"-Dpybind11_DIR={pybind11.get_cmake_dir()}",
                        *os.environ.get("CMAKE_ARGS", "").split()], check=True)
        # Four translation units: more jobs than that do not help.
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(min(4, os.cpu_count() or 1))
        subprocess.run(["cmake", "--build", str(build), "--target", "sphere_python", "--parallel", jobs], check=True)
        built = next((build / "python" / "sphere").glob("_sphere.*"))
        destination = Path(self.get_ext_fullpath(ext.name))
        destination.parent.mkdir(parents=True, exist_ok=True)
        self.copy_file(str(built), str(destination))


# setuptools writes its package metadata (sphere.egg-info) beside its build folders in build/,
# which git ignores, instead of into python/.
os.makedirs("build", exist_ok=True)

setup(
    version=project_version(),
    packages=["sphere"],
    package_dir={"": "python"},
    ext_modules=[Extension("sphere._sphere", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"egg_info": {"egg_base": "build"}},
)
