"""The walk-through script of docs/python.md runs as written and prints what the page shows."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

matplotlib = pytest.importorskip("matplotlib", reason="the walk-through draws figures with matplotlib")
import matplotlib.image  # noqa: E402


def test_walkthrough(tmp_path):
    page = (Path(os.environ["SPHERE_SOURCE_DIR"]) / "docs" / "python.md").read_text()
    section = page[page.index("## Walk-through"):]
    script, printed = re.findall(r"```(?:python)?\n(.*?)```", section, re.S)[:2]
    done = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout == printed
    assert (tmp_path / "loaded.ck").exists()
    for figure in ("walls.png", "rose.png", "porosity.png"):
        assert matplotlib.image.imread(tmp_path / figure).shape[2] == 4, figure  # RGBA
