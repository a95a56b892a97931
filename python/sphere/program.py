"""The sphere program (apps/sphere, docs/program.md) from Python, as the original sphere's
sim.run() and sim.status(): run a checkpoint to a total simulated time in a child process, then
read its status file and its numbered output checkpoints (<name>.output<NNNNN>.ck).
"""

import os
import re
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

from ._sphere import Error
from .simulation import read_checkpoint

PROGRAM_VARIABLE = "SPHERE_PROGRAM"


def find_program(program=None):
    """The path of the sphere program: `program` when given (it must be an executable file),
    else the environment variable SPHERE_PROGRAM, else `sphere` on PATH. Raises sphere.Error
    saying where it looked when there is none."""
    if program is not None:
        where = f"program = '{os.fspath(program)}'"
        candidate = os.fspath(program)
    elif os.environ.get(PROGRAM_VARIABLE):
        where = f"{PROGRAM_VARIABLE} = '{os.environ[PROGRAM_VARIABLE]}'"
        candidate = os.environ[PROGRAM_VARIABLE]
    else:
        found = shutil.which("sphere")
        if found is None:
            raise Error("sphere: the sphere program was not found: give program=, set "
                        f"{PROGRAM_VARIABLE} or put 'sphere' on PATH (target sphere_program builds build/apps/sphere)")
        return found
    if not (os.path.isfile(candidate) and os.access(candidate, os.X_OK)):
        raise Error(f"sphere: {where}: not an executable file")
    return candidate


def run_name(checkpoint):
    """The name the program gives a run's files: the checkpoint's file name without its folder
    and its extension ('runs/sample.ck' -> 'sample')."""
    return Path(os.fspath(checkpoint)).stem


@dataclass
class Status:
    """A run's status file (<out>/<name>.status.dat): the simulated time of the last output (s),
    the percentage of the run done, the number of the last output, and the lines that identify
    the run (`identity`: input, input_checksum, run, first_step, last_step, output_every)."""

    time: float
    percent: float
    last_output: int
    identity: dict = field(default_factory=dict)


def status(out, name):
    """The status of run `name` in folder `out` (sphere's status()). Raises sphere.Error when the
    file is missing or not a status file."""
    path = Path(os.fspath(out)) / f"{name}.status.dat"
    try:
        lines = path.read_text().splitlines()
    except OSError as e:
        raise Error(f"sphere: status file '{path}': cannot read it ({e.strerror})") from None
    first = lines[0].split() if lines else []
    try:
        time, percent, last = float(first[0]), float(first[1]), int(first[2])
    except (IndexError, ValueError):
        raise Error(f"sphere: status file '{path}': its first line is not 'time percent last-output'") from None
    identity = {}
    for line in lines[1:]:
        key, _, value = line.partition(" ")
        identity[key] = value
    return Status(time, percent, last, identity)


_NUMBERED = re.compile(r"\.output(\d{5,})\.ck$")


def outputs(out, name):
    """The numbered output checkpoints of run `name` in folder `out`, as Paths in the order of
    their numbers (empty when there are none)."""
    folder = Path(os.fspath(out))
    found = []
    for path in folder.glob(f"{glob_escape(name)}.output*.ck"):
        m = _NUMBERED.search(path.name)
        if m and path.name == f"{name}.output{m.group(1)}.ck":
            found.append((int(m.group(1)), path))
    return [path for _, path in sorted(found)]


def glob_escape(text):
    """`text` with glob's special characters escaped."""
    return re.sub(r"([*?\[])", r"[\1]", text)


def read_output(out, name, k=-1, precision=None):
    """A Simulation continuing output `k` of run `name` in folder `out` (its checkpoint
    <name>.output<k, 5 digits>.ck; k = -1: the last one written), in `precision` (by default the
    file's). Raises sphere.Error when there is no such output."""
    if k < 0:
        found = outputs(out, name)
        if len(found) < -k:
            raise Error(f"sphere: read_output: folder '{os.fspath(out)}' holds {len(found)} outputs of '{name}'; "
                        f"output {k} is not there")
        path = found[k]
    else:
        path = Path(os.fspath(out)) / f"{name}.output{k:05d}.ck"
        if not path.exists():
            raise Error(f"sphere: read_output: '{path}' does not exist")
    return read_checkpoint(path, precision)


@dataclass
class ProgramRun:
    """A finished run of the sphere program: its output folder, the run's name, its numbered
    output checkpoints (Paths) and its status."""

    out: Path
    name: str
    outputs: list
    status: Status


def run_program(checkpoint, total, interval=None, out="output", precision=None, integrator="euler", program=None,
                vtk=True, fresh=False, threads=None):
    """Runs the sphere program on `checkpoint` until the simulated time `total` (s, counted from
    the simulation's start), writing numbered output checkpoints every `interval` (s; by default
    a tenth of the run) into folder `out` (and VTK frames unless `vtk` is False). `precision`:
    'float', 'double' or None (the file's); `integrator`: 'euler' or 'verlet'; `fresh`: replace
    an earlier run of the same input in `out` (otherwise a matching one is resumed, another
    refused); `threads`: OMP_NUM_THREADS for the run (by default the caller's). `program`: see
    find_program. Waits for the program to end and returns a ProgramRun; raises sphere.Error
    with the program's message when it fails."""
    command = [find_program(program), os.fspath(checkpoint), "--total", repr(float(total)), "-o", os.fspath(out),
               "--precision", precision or "file", "--integrator", integrator, "-q"]
    if interval is not None:
        command += ["--interval", repr(float(interval))]
    if not vtk:
        command.append("--no-vtk")
    if fresh:
        command.append("--fresh")
    environment = dict(os.environ)
    if threads is not None:
        environment["OMP_NUM_THREADS"] = str(int(threads))
    done = subprocess.run(command, capture_output=True, text=True, env=environment)
    if done.returncode != 0:
        message = (done.stderr.strip() or done.stdout.strip()).splitlines()
        text = message[-1] if message else "no message"
        if not text.startswith("sphere: "):
            text = "sphere: " + text
        raise Error(f"{text} (the sphere program exited with status {done.returncode})")
    name = run_name(checkpoint)
    return ProgramRun(Path(os.fspath(out)), name, outputs(out, name), status(out, name))
