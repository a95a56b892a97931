"""A film of numbered pictures: the frames <name>.output00000.png, <name>.output00001.png, ...
(e.g. Simulation.render of each output of a run, named as the sphere program names its
outputs) joined into an MP4 video by ffmpeg, as the original sphere's video(). ffmpeg runs as a
subprocess, without a shell."""

import os
import shutil
import subprocess

from ._sphere import Error


def film(folder, name, fps=10, out=None, ffmpeg=None):
    """Joins the frames `folder`/<name>.output%05d.png (numbered from 0 without gaps) into the
    H.264 video `out` (by default `folder`/<name>.mp4) at `fps` frames per second (1/s), with
    ffmpeg (`ffmpeg`, else the one on PATH). Returns the video's path. Raises sphere.Error when
    ffmpeg is not installed, when there is no first frame, or when ffmpeg fails (with its
    message)."""
    folder = os.fspath(folder)
    if not (isinstance(fps, (int, float)) and fps > 0):
        raise Error(f"sphere: film: fps = {fps!r}: a positive number of frames per second is needed")
    program = ffmpeg or shutil.which("ffmpeg")
    if program is None:
        raise Error("sphere: film: ffmpeg was not found on PATH: install it (Debian's ffmpeg) or give ffmpeg=")
    pattern = os.path.join(folder, f"{name}.output%05d.png")
    if not os.path.isfile(pattern % 0):
        raise Error(f"sphere: film: no frame '{pattern % 0}' (the frames are {pattern}, numbered from 0)")
    out = os.fspath(out) if out is not None else os.path.join(folder, f"{name}.mp4")
    # yuv420p and even sizes: the H.264 that players read.
    command = [program, "-y", "-loglevel", "error", "-framerate", str(fps), "-start_number", "0", "-i", pattern,
               "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p", out]
    try:
        done = subprocess.run(command, capture_output=True, text=True)
    except OSError as e:
        raise Error(f"sphere: film: cannot run ffmpeg '{program}': {e}") from None
    if done.returncode != 0:
        raise Error(f"sphere: film: ffmpeg failed (exit status {done.returncode}): {done.stderr.strip()}")
    return out
