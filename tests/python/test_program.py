"""sphere.run_program, status, outputs and read_output: a checkpoint written by Python, run by
the sphere program, and its last output against an in-process run of the same steps (the same
bytes when written back); the status file; finding the program and its errors."""

import os

import pytest
from conftest import cpp_program

import sphere


def sample(precision, path):
    """A 60-particle sample poured for 0.1 s, written to `path`; returns the Simulation."""
    sim = sphere.deposited_sample(particles=60, precision=precision)
    sim.write_checkpoint(path)
    return sim


def test_program_run_equals_an_in_process_run(precision, tmp_path):
    program = cpp_program("SPHERE_PROGRAM", "the sphere program")
    sim = sample(precision, tmp_path / "sand.ck")
    total = sim.time + 0.05
    run = sphere.run_program(tmp_path / "sand.ck", total, interval=0.01, out=tmp_path / "out", program=program,
                             threads=1)
    assert run.name == "sand"
    # Outputs 0 (the input's state) to 5, every round(0.01 / dt) steps, the last one at the end.
    assert [p.name for p in run.outputs] == [f"sand.output{k:05d}.ck" for k in range(len(run.outputs))]
    assert run.status.last_output == len(run.outputs) - 1 >= 5
    assert run.status.percent == 100
    first, last = int(run.status.identity["first_step"]), int(run.status.identity["last_step"])
    assert first == sim.steps and last * sim.dt >= total - 1e-9 * sim.dt
    assert run.status.identity["input"] == str(tmp_path / "sand.ck")

    ended = sphere.read_output(tmp_path / "out", "sand", precision=None)
    assert ended.precision == precision and ended.steps == last
    assert ended.time == run.status.time
    sim.run(last - first)  # the same steps in this process
    sim.write_checkpoint(tmp_path / "here.ck")
    ended.write_checkpoint(tmp_path / "there.ck")
    assert (tmp_path / "there.ck").read_bytes() == (tmp_path / "here.ck").read_bytes()
    assert (tmp_path / "there.ck").read_bytes() == run.outputs[-1].read_bytes()
    # Output 0 is the input.
    assert sphere.read_output(tmp_path / "out", "sand", 0).steps == first
    assert sphere.status(tmp_path / "out", "sand") == run.status


def test_finding_the_program(tmp_path, monkeypatch):
    monkeypatch.delenv("SPHERE_PROGRAM", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(sphere.Error, match="the sphere program was not found: give program=, set SPHERE_PROGRAM"):
        sphere.find_program()
    with pytest.raises(sphere.Error, match=r"program = '.*nothing': not an executable file"):
        sphere.find_program(tmp_path / "nothing")
    monkeypatch.setenv("SPHERE_PROGRAM", str(tmp_path / "nothing"))
    with pytest.raises(sphere.Error, match=r"SPHERE_PROGRAM = '.*nothing': not an executable file"):
        sphere.run_program(tmp_path / "a.ck", 1.0)
    fake = tmp_path / "sphere"
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    monkeypatch.delenv("SPHERE_PROGRAM")
    assert sphere.find_program() == str(fake)


def test_program_errors(tmp_path):
    program = cpp_program("SPHERE_PROGRAM", "the sphere program")
    with pytest.raises(sphere.Error, match=r"sphere: checkpoint '.*missing.ck': cannot open.*exited with status 1"):
        sphere.run_program(tmp_path / "missing.ck", 1.0, out=tmp_path / "out", program=program)
    sim = sample("double", tmp_path / "sand.ck")
    with pytest.raises(sphere.Error, match=r"--total 0.01 s: must be finite and at least the input's time"):
        sphere.run_program(tmp_path / "sand.ck", 0.01, out=tmp_path / "out", program=program)
    assert sim.time > 0.01
    with pytest.raises(sphere.Error, match=r"status file '.*sand.status.dat': cannot read it"):
        sphere.status(tmp_path / "out", "sand")
    (tmp_path / "out").mkdir(exist_ok=True)
    (tmp_path / "out" / "sand.status.dat").write_text("nonsense\n")
    with pytest.raises(sphere.Error, match="its first line is not 'time percent last-output'"):
        sphere.status(tmp_path / "out", "sand")
    assert sphere.outputs(tmp_path / "out", "sand") == []
    with pytest.raises(sphere.Error, match="holds 0 outputs of 'sand'; output -1 is not there"):
        sphere.read_output(tmp_path / "out", "sand")
    with pytest.raises(sphere.Error, match=r"sand.output00003.ck' does not exist"):
        sphere.read_output(tmp_path / "out", "sand", 3)
    assert os.listdir(tmp_path / "out") == ["sand.status.dat"]
