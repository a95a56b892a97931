"""`pip install .` builds and installs the package (setup.py, the project's CMake): installed
into a fresh folder from a copy of the sources (so that pip's build folders stay out of the
checkout), it imports from there, runs and renders a picture (libpng linked). Slow: it compiles the extension module again."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

SOURCES = ["CMakeLists.txt", "LICENSE", "README.md", "cmake", "include", "pyproject.toml", "python", "setup.py"]

CHECK = """
import sphere
print(sphere.__file__)
print(sphere.__version__)
contact = sphere.ContactParams(k_n=1e5, k_t=1e5)
s = sphere.Settings(gravity=(0, 0, -9.81), contact=contact, wall=contact)
sim = sphere.Simulation(s, [[0.5, 0.5, 0.5]], 0.01, 2500, precision="float")
sim.run(100)
print(sim.steps, float(sim.snapshot().positions[0, 2]) < 0.5)
if sphere._sphere.has_png:  # libpng linked where the build found it
    sim.render("picture.png", method="vel")
    with open("picture.png", "rb") as f:
        print(f.read(4)[1:] == b"PNG")  # the PNG signature
else:
    print("no libpng")
"""


def test_pip_install(tmp_path):
    root = Path(os.environ["SPHERE_SOURCE_DIR"])
    source = tmp_path / "source"
    source.mkdir()
    for name in SOURCES:
        if (root / name).is_dir():
            shutil.copytree(root / name, source / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(root / name, source / name)
    target = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-build-isolation", "--no-deps", "--no-cache-dir",
                    "--target", str(target), str(source)], check=True)
    env = dict(os.environ, PYTHONPATH=str(target))
    done = subprocess.run([sys.executable, "-c", CHECK], env=env, cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    where, version, run, picture = done.stdout.splitlines()
    assert Path(where).parent == target / "sphere"
    import sphere

    assert version == sphere.__version__
    assert run == "100 True"
    # libpng as in the build under test (the same machine finds the same libraries).
    assert picture == ("True" if sphere._sphere.has_png else "no libpng")
