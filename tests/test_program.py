#!/usr/bin/env python3
"""The `sphere` program (apps/sphere/main.cpp, docs/program.md), end to end.

Usage: test_program.py SPHERE INPUT.ck SCRATCH

- A run killed with SIGKILL after some outputs and started again resumes from its last output,
  and every file it leaves (numbered checkpoints, VTK frames, the .pvd, the status file) equals
  the uninterrupted run's byte for byte; in the checkpoint's precision (float, the consolidation
  example's checkpoint) and in double with velocity Verlet.
- The plan: the run ends at the first step at or after --total, outputs every interval, the
  status file's first line (time, percent, last output) as the original sphere's status.dat.
- --render: a picture of the input alone (without --total), and one per output of a run, PNG
  files that Pillow opens (800 x 800 RGB, the method and colour-map range in their text).
- --dry prints the settings and the plan and writes nothing; --version; bad input (missing,
  truncated and foreign files, a total before the input's time, another run in the folder, the
  CUDA backend in a host build) gives exit status 1 and a message naming the value.
- The CUDA build (sphere-cuda, whose --version lists the cuda backend) passes the same checks on
  its host backend; its --backend cuda stops before writing anything where there is no CUDA
  device, and where there is one its run resumes after SIGKILL byte for byte too.
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import time

SPHERE, INPUT, SCRATCH = sys.argv[1], sys.argv[2], sys.argv[3]
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print("FAIL:", what)


def run(*args, expect=0, env=None):
    r = subprocess.run([SPHERE, *args], capture_output=True, text=True, timeout=300, env=env)
    check(r.returncode == expect, f"sphere {' '.join(args)}: exit {r.returncode}, expected {expect}\n{r.stdout}{r.stderr}")
    return r


def status(folder, name="input"):
    with open(os.path.join(folder, name + ".status.dat")) as f:
        lines = f.read().splitlines()
    t, percent, last = lines[0].split()
    return float(t), float(percent), int(last), lines[1:]


shutil.rmtree(SCRATCH, ignore_errors=True)
os.makedirs(SCRATCH)
input_ck = os.path.join(SCRATCH, "input.ck")
shutil.copyfile(INPUT, input_ck)

# The input's time and time step from --dry.
dry = run(input_ck, "--dry", "-o", os.path.join(SCRATCH, "dry"))
dt = float(re.search(r"^time step\s+(\S+) s", dry.stdout, re.M).group(1))
t0 = float(re.search(r"^time\s+(\S+) s \(step (\d+)\)", dry.stdout, re.M).group(1))
first = int(re.search(r"^time\s+\S+ s \(step (\d+)\)", dry.stdout, re.M).group(1))
check("(no --total given: a run needs one)" in dry.stdout, "--dry without --total says a run needs one")
check(re.search(r"^particles\s+150$", dry.stdout, re.M) is not None, "--dry prints the particle count")
check(abs(t0 - first * dt) <= 1e-6 * t0, f"--dry: the input's time {t0} is its step {first} x dt {dt}")

total, interval = t0 + 1.0, 0.05
every = round(interval / dt)
last = first + int(-(-(total / dt - first) // 1))  # the first step at or after total
outputs = -(-(last - first) // every) + 1
dry = run(input_ck, "--dry", "-t", str(total), "-i", str(interval), "-o", os.path.join(SCRATCH, "dry"))
check(f"to {last * dt:.9g} s (step {last}): {last - first} steps" in dry.stdout,
      f"--dry plans steps {first} to {last}:\n{dry.stdout}")
check(f"outputs        {outputs}, every {every} steps" in dry.stdout, f"--dry plans {outputs} outputs every {every} steps")
check(not os.path.exists(os.path.join(SCRATCH, "dry")), "--dry writes nothing")


def killed_and_resumed(tag, *options):
    """An uninterrupted run and one killed (SIGKILL) after its third output, then resumed:
    every file of both equal byte for byte."""
    whole, broken = os.path.join(SCRATCH, tag + "-whole"), os.path.join(SCRATCH, tag + "-broken")
    args = [input_ck, "-t", str(total), "-i", str(interval), *options]
    run(*args, "-q", "-o", whole)
    t_end, percent, last_output, identity = status(whole)
    check(last_output == outputs - 1 and percent == 100, f"{tag}: status says output {last_output} of {outputs - 1}, {percent}%")
    check(t_end >= total and t_end - total < dt * 1.0001, f"{tag}: the run ends at {t_end} s, the first step at or after {total} s")
    check(any(line.startswith("input_checksum ") for line in identity), f"{tag}: the status file identifies the input")

    p = subprocess.Popen([SPHERE, *args, "-q", "-o", broken], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    seen = -1
    deadline = time.time() + 120
    while p.poll() is None and time.time() < deadline:
        try:
            seen = status(broken)[2]
        except (OSError, ValueError, IndexError):
            pass
        if seen >= 3:
            p.send_signal(signal.SIGKILL)
            break
        time.sleep(0.002)
    p.wait()
    check(p.returncode == -signal.SIGKILL, f"{tag}: the run was killed mid-way (exit {p.returncode}, output {seen})")
    killed_at = status(broken)[2]
    check(killed_at < outputs - 1, f"{tag}: killed before the end (output {killed_at} of {outputs - 1})")
    resumed = run(*args, "-o", broken)  # without -q: it says where it resumes
    check(f"resuming from output {killed_at} " in resumed.stdout, f"{tag}: resumes from output {killed_at}:\n{resumed.stdout}")
    names = sorted(os.listdir(whole))
    check(names == sorted(os.listdir(broken)), f"{tag}: the same files ({len(names)})")
    check(len([n for n in names if n.endswith(".ck")]) == outputs, f"{tag}: {outputs} numbered checkpoints")
    for n in names:
        with open(os.path.join(whole, n), "rb") as a, open(os.path.join(broken, n), "rb") as b:
            check(a.read() == b.read(), f"{tag}: {n} equals the uninterrupted run's")
    # Started again, with the input named another way: the same run (its checksum), finished.
    again = run(os.path.join(SCRATCH, ".", "input.ck"), *args[1:], "-o", broken)
    check(f"resuming from output {outputs - 1} " in again.stdout, f"{tag}: a finished run started again does nothing more")
    return whole


whole = killed_and_resumed("file")
killed_and_resumed("double-verlet", "--precision", "double", "--integrator", "verlet")

# Pictures (Pillow, Debian's python3-pil for /usr/bin/python3).
from PIL import Image  # noqa: E402

pictures = os.path.join(SCRATCH, "pictures")
said = run(input_ck, "--render", "pres", "-o", pictures)
check("picture of" in said.stdout and os.path.isfile(os.path.join(pictures, "input.png")), "--render without --total: one picture")
with Image.open(os.path.join(pictures, "input.png")) as im:
    check(im.size == (800, 800) and im.mode == "RGB", f"the picture is 800 x 800 RGB: {im.size} {im.mode}")
    check(im.info.get("sphere field") == "pres" and float(im.info.get("sphere max_val", "0")) > 0,
          f"its text names the method and a positive top of the colour map: {im.info}")
    colours = im.getcolors(1 << 24)  # (count, colour) pairs; getdata() is deprecated in Pillow 12
    check(len(colours) > 50, "the picture shows shaded, coloured spheres")
run(input_ck, "-t", str(t0 + 2 * interval), "-i", str(interval), "-q", "--no-vtk", "--render", "xdisp",
    "--max-val", "0.001", "-o", pictures)
shots = sorted(n for n in os.listdir(pictures) if n.startswith("input.output") and n.endswith(".png"))
outputs_there = sorted(n for n in os.listdir(pictures) if n.startswith("input.output") and n.endswith(".ck"))
check(len(shots) >= 3 and [n[:-4] for n in shots] == [n[:-3] for n in outputs_there],
      f"one picture per output: {shots}, {outputs_there}")
for n in shots:
    with Image.open(os.path.join(pictures, n)) as im:
        check(im.size == (800, 800) and im.info.get("sphere field") == "xdisp" and im.info.get("sphere max_val") == "0.001",
              f"{n}: {im.size}, {im.info}")
# --film: ffmpeg started with the pictures and the film's path (a stand-in ffmpeg on the PATH
# records its arguments and writes the film), and a note when there is none.
tools = os.path.join(SCRATCH, "tools")
os.makedirs(tools)
with open(os.path.join(tools, "ffmpeg"), "w") as f:
    f.write('#!/bin/sh\nprintf "%s\\n" "$@" > "$(dirname "$0")/arguments"\nfor last; do :; done\necho film > "$last"\n')
os.chmod(os.path.join(tools, "ffmpeg"), 0o755)
film_dir = os.path.join(SCRATCH, "film")
with_ffmpeg = dict(os.environ, PATH=tools + os.pathsep + os.environ["PATH"])
filmed = run(input_ck, "-t", str(t0 + 2 * interval), "-i", str(interval), "--no-vtk", "-r", "vel", "--film", "--fps", "5",
             "-o", film_dir, env=with_ffmpeg)
with open(os.path.join(tools, "arguments")) as f:
    arguments = f.read().split("\n")
check(os.path.join(film_dir, "input.output%05d.png") in arguments and arguments[arguments.index("-framerate") + 1] == "5.000000"
      and os.path.isfile(os.path.join(film_dir, "input.mp4")) and "input.mp4" in filmed.stdout,
      f"--film runs ffmpeg on the pictures: {arguments}\n{filmed.stdout}")
without = dict(os.environ, PATH=os.path.dirname(shutil.which("sh")))
bare = run(input_ck, "-t", str(t0 + interval), "-i", str(interval), "-q", "--no-vtk", "-r", "vel", "--film",
           "-o", os.path.join(SCRATCH, "no-film"), env=without)
check("--film: no ffmpeg on the PATH" in bare.stderr, f"--film without ffmpeg says so: {bare.stderr}")
check("--film requires --render" in run(input_ck, "-t", "1", "--film", expect=107).stderr, "--film needs --render")
bad_method = run(input_ck, "--render", "colour", expect=105)
check("--render: colour not in {" in bad_method.stderr, f"an unknown method is refused: {bad_method.stderr}")

# Bad input: exit status 1 and a message that names the value.
version = run("--version")
check(re.match(r"sphere \d+\.\d+\.\d+ \(checkpoint format \d+, backends: host(, cuda)?\)", version.stdout) is not None,
      "--version")
CUDA_BUILD = "backends: host, cuda" in version.stdout

if CUDA_BUILD:
    probe_dir = os.path.join(SCRATCH, "cuda-probe")
    probe = subprocess.run([SPHERE, input_ck, "-t", str(t0 + interval), "-q", "--backend", "cuda", "-o", probe_dir],
                           capture_output=True, text=True, timeout=300)
    if probe.returncode == 1 and "--backend cuda: no CUDA device (" in probe.stderr:
        check(not os.path.exists(probe_dir), "--backend cuda without a device writes nothing")
        print("no CUDA device here: the cuda backend's runs are not checked")
    else:
        check(probe.returncode == 0, f"--backend cuda: exit {probe.returncode}\n{probe.stderr}")
        killed_and_resumed("cuda", "--backend", "cuda")


def refused(pattern, *args):
    r = run(*args, expect=1)
    check(re.search(pattern, r.stderr) is not None, f"sphere {' '.join(args)}: message /{pattern}/, got:\n{r.stderr}")


missing = os.path.join(SCRATCH, "missing.ck")
refused(r"checkpoint '.*missing\.ck': cannot open: No such file", missing, "-t", "1")
truncated = os.path.join(SCRATCH, "truncated.ck")
with open(input_ck, "rb") as f:
    data = f.read()
with open(truncated, "wb") as f:
    f.write(data[: len(data) // 2])
refused(r"checkpoint '.*truncated\.ck': truncated: the file has \d+ bytes", truncated, "-t", "1")
foreign = os.path.join(SCRATCH, "foreign.ck")
with open(foreign, "w") as f:
    f.write("particles, 1, 2, 3\n")
refused(r"not a sphere checkpoint", foreign, "-t", "1")
refused(r"--total 0\.1 s: must be finite and at least the input's time", input_ck, "-t", "0.1", "-o", os.path.join(SCRATCH, "early"))
refused(r"--interval -1 s: must be positive", input_ck, "-t", str(total), "-i", "-1", "-o", os.path.join(SCRATCH, "neg"))
refused(r"--total: the simulated time to run to \(s\) is required", input_ck, "-o", os.path.join(SCRATCH, "none"))
refused(r"holds another run of 'input' \(last_step \d+ there, \d+ here\): give --fresh",
        input_ck, "-t", str(total + 0.5), "-i", str(interval), "-q", "-o", whole)
if not CUDA_BUILD:
    refused(r"--backend cuda: this sphere program was built for the host backend only; its CUDA build is sphere-cuda",
            input_ck, "-t", "1", "--backend", "cuda")
fresh = run(input_ck, "-t", str(t0 + 0.1), "-i", str(interval), "-q", "--fresh", "-o", whole)
short_last = int(status(whole)[3][4].split()[1])  # the status file's last_step line
check(short_last == first + round(0.1 / dt) or short_last == first + round(0.1 / dt) + 1, f"--fresh: the shorter run's last step {short_last}")
check(len([n for n in os.listdir(whole) if n.endswith(".ck")]) == -(-(short_last - first) // every) + 1,
      "--fresh replaces the earlier run's files")

if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("all checks passed")
