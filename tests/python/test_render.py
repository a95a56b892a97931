"""Simulation.render (the library's ray tracer, a PNG through libpng) and sphere.film (ffmpeg):
the pictures open with Pillow at 800 x 800 with the method and range in their text; film runs a
stand-in ffmpeg, first on PATH, that records its arguments, and names ffmpeg when there is none."""

import os
import sys

import numpy as np
import pytest
from conftest import linear_settings

import sphere
from sphere import _sphere

Image = pytest.importorskip("PIL.Image", reason="the pictures are read with Pillow (python3-pil)")

needs_png = pytest.mark.skipif(not _sphere.has_png, reason="the package was built without libpng")


@pytest.fixture
def moving(precision):
    """Nine particles in a row, the k-th moving at k cm/s along x (nothing touches)."""
    s = linear_settings(hi=(1.0, 1.0, 1.0))
    positions = [[0.1 + 0.1 * k, 0.5, 0.5] for k in range(9)]
    velocities = [[0.01 * k, 0.0, 0.0] for k in range(9)]
    return sphere.Simulation(s, positions, 0.04, 2500, velocities=velocities, precision=precision)


@needs_png
def test_render_writes_each_method(moving, tmp_path):
    for method in ["normal", "pres", "vel", "angvel", "xdisp"]:
        path = tmp_path / f"{method}.png"
        moving.render(path, method=method)
        with Image.open(path) as image:
            assert image.format == "PNG" and image.size == (800, 800) and image.mode == "RGB"
            assert image.text["sphere field"] == method
            assert image.text["Software"] == "sphere"
            pixels = np.asarray(image)
        assert (pixels != 255).any()  # particles drawn on the white background
        if method == "normal":
            assert "sphere max_val" not in image.text  # no colour bar, no range
    # vel: the range is the speeds' by default, or as given.
    with Image.open(tmp_path / "vel.png") as image:
        assert float(image.text["sphere max_val"]) == pytest.approx(0.08, rel=1e-6)
        assert float(image.text["sphere lower_cutoff"]) == 0.0
    moving.render(tmp_path / "given.png", method="vel", max_val=0.5, lower_cutoff=0.02)
    with Image.open(tmp_path / "given.png") as image:
        assert image.text["sphere max_val"] == "0.5" and image.text["sphere lower_cutoff"] == "0.02"
        given = np.asarray(image)
    with Image.open(tmp_path / "vel.png") as image:
        assert not np.array_equal(np.asarray(image), given)  # the slow particles are left out


@needs_png
def test_render_errors(moving, tmp_path):
    with pytest.raises(sphere.Error, match=r"render: unknown method 'pressure' \(normal, pres, vel, angvel or xdisp"):
        moving.render(tmp_path / "x.png", method="pressure")
    with pytest.raises(sphere.Error, match=r"render: max_val = 1 must be finite and above lower_cutoff = 2"):
        moving.render(tmp_path / "x.png", method="vel", max_val=1.0, lower_cutoff=2.0)
    with pytest.raises(sphere.Error, match=r"cannot write '.*/missing/x.png'"):
        moving.render(tmp_path / "missing" / "x.png")
    assert sorted(os.listdir(tmp_path)) == []


def stand_in_ffmpeg(folder):
    """An executable `ffmpeg` in `folder` that writes its arguments, one a line, to args.txt
    beside it, creates its last argument (the video) and exits 0."""
    fake = folder / "ffmpeg"
    fake.write_text(f"#!{sys.executable}\n"
                    "import pathlib, sys\n"
                    "here = pathlib.Path(sys.argv[0]).parent\n"
                    "(here / 'args.txt').write_text('\\n'.join(sys.argv[1:]))\n"
                    "pathlib.Path(sys.argv[-1]).write_bytes(b'video')\n")
    fake.chmod(0o755)
    return fake


def test_film_runs_ffmpeg(tmp_path, monkeypatch):
    tools, frames = tmp_path / "bin", tmp_path / "frames"
    tools.mkdir()
    frames.mkdir()
    stand_in_ffmpeg(tools)
    monkeypatch.setenv("PATH", f"{tools}{os.pathsep}{os.environ.get('PATH', '')}")
    for k in range(3):
        (frames / f"run.output{k:05d}.png").write_bytes(b"png")
    out = sphere.film(frames, "run", fps=25)
    assert out == str(frames / "run.mp4") and (frames / "run.mp4").read_bytes() == b"video"
    args = (tools / "args.txt").read_text().split("\n")
    assert args[args.index("-framerate") + 1] == "25"
    assert args[args.index("-i") + 1] == str(frames / "run.output%05d.png")
    assert args[args.index("-start_number") + 1] == "0"
    assert args[-1] == str(frames / "run.mp4")
    # Another output, default fps.
    sphere.film(frames, "run", out=tmp_path / "other.mp4")
    args = (tools / "args.txt").read_text().split("\n")
    assert args[args.index("-framerate") + 1] == "10" and args[-1] == str(tmp_path / "other.mp4")


def test_film_errors(tmp_path, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))  # no ffmpeg anywhere
    with pytest.raises(sphere.Error, match=r"^sphere: film: ffmpeg was not found on PATH"):
        sphere.film(tmp_path, "run")
    tools = tmp_path / "bin"
    tools.mkdir()
    stand_in_ffmpeg(tools)
    monkeypatch.setenv("PATH", str(tools))
    with pytest.raises(sphere.Error, match=r"film: no frame '.*run.output00000.png'"):
        sphere.film(tmp_path, "run")
    with pytest.raises(sphere.Error, match=r"film: fps = 0: a positive number"):
        sphere.film(tmp_path, "run", fps=0)
    failing = tools / "ffmpeg"
    failing.write_text("#!/bin/sh\necho 'Unknown encoder libx264' >&2\nexit 3\n")
    (tmp_path / "run.output00000.png").write_bytes(b"png")
    with pytest.raises(sphere.Error, match=r"film: ffmpeg failed \(exit status 3\): Unknown encoder libx264"):
        sphere.film(tmp_path, "run")
