"""Checkpoints between C++ and Python: a checkpoint the C++ consolidation example wrote is read
and written back byte for byte; steps run in Python after reading it give the same bytes as the
same steps run by the example; the other precision, another contact law and broken files."""

import re

import numpy as np
import pytest

import sphere


def fnv1a64(data):
    """The checkpoint's checksum (FNV-1a, 64 bit)."""
    h = 14695981039346656037
    for byte in data:
        h = ((h ^ byte) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h


def with_law(data, law):
    """A checkpoint's bytes with the contact law's name (the payload's first text) replaced by
    `law`, the payload size and the checksum updated; and the name it had."""
    header, payload = data[:24], data[24:-8]
    length = int.from_bytes(payload[:8], "little")
    old = payload[8:8 + length].decode()
    payload = len(law).to_bytes(8, "little") + law.encode() + payload[8 + length:]
    body = header[:16] + len(payload).to_bytes(8, "little") + payload
    return body + fnv1a64(body).to_bytes(8, "little"), old


def test_cpp_checkpoint_written_back_byte_for_byte(cpp_consolidation, precision, tmp_path):
    path, _ = cpp_consolidation(precision, 0.01)
    sim = sphere.read_checkpoint(path)
    assert sim.precision == precision  # the writer's
    assert sim.size == 150 and sim.steps > 0
    sim.write_checkpoint(tmp_path / "again.ck")
    assert (tmp_path / "again.ck").read_bytes() == path.read_bytes()


def test_steps_after_reading_equal_the_cpp_steps(cpp_consolidation, precision, tmp_path):
    # The example loads for 0.01 s and for 0.02 s; Python continues the first to the second's step.
    short, _ = cpp_consolidation(precision, 0.01)
    long, _ = cpp_consolidation(precision, 0.02)
    sim = sphere.read_checkpoint(short)
    target = sphere.read_checkpoint(long).steps
    assert target > sim.steps
    sim.run(target - sim.steps)
    sim.write_checkpoint(tmp_path / "continued.ck")
    assert (tmp_path / "continued.ck").read_bytes() == long.read_bytes()


def test_python_restart_in_two_halves(cpp_consolidation, precision, tmp_path):
    path, _ = cpp_consolidation(precision, 0.01)
    whole = sphere.read_checkpoint(path)
    whole.run(400)
    whole.write_checkpoint(tmp_path / "whole.ck")
    half = sphere.read_checkpoint(path)
    half.run(200)
    half.write_checkpoint(tmp_path / "half.ck")
    rest = sphere.read_checkpoint(tmp_path / "half.ck")
    rest.run(200)
    rest.write_checkpoint(tmp_path / "halves.ck")
    assert (tmp_path / "halves.ck").read_bytes() == (tmp_path / "whole.ck").read_bytes()
    np.testing.assert_array_equal(rest.snapshot().positions, whole.snapshot().positions)


def test_read_in_the_other_precision(cpp_consolidation, precision):
    path, _ = cpp_consolidation(precision, 0.01)
    other = "double" if precision == "float" else "float"
    written = sphere.read_checkpoint(path)
    sim = sphere.read_checkpoint(path, precision=other)
    assert sim.precision == other and sim.steps == written.steps
    # Values are stored as doubles and converted exactly (float -> double) or rounded (double -> float).
    dtype = np.float32 if other == "float" else np.float64
    assert sim.snapshot().positions.dtype == dtype
    np.testing.assert_array_equal(sim.snapshot().positions, written.snapshot().positions.astype(dtype))
    sim.run(10)
    assert sim.steps == written.steps + 10


def test_checkpoint_of_another_contact_law(cpp_consolidation, tmp_path):
    path, _ = cpp_consolidation("double", 0.01)
    data, law = with_law(path.read_bytes(), "hertz_mindlin<elastic_viscous_frictional, visco_frictional>")
    assert law.startswith("linear<")
    other = tmp_path / "hertz.ck"
    other.write_bytes(data)
    history = "tangential displacement (m) xyz, sliding flag w"
    with pytest.raises(sphere.Error) as e:
        sphere.read_checkpoint(other)
    assert str(e.value) == (
        f"sphere: checkpoint '{other}': written with the contact law hertz_mindlin<elastic_viscous_frictional, "
        f"visco_frictional> (history: {history}), but the reader uses {law} (history: {history}); restart it with "
        "the same law")


def test_missing_and_corrupt_checkpoints(cpp_consolidation, tmp_path):
    missing = tmp_path / "missing.ck"
    with pytest.raises(sphere.Error, match=re.escape(f"sphere: checkpoint '{missing}': cannot open: No such file")):
        sphere.read_checkpoint(missing)
    path, _ = cpp_consolidation("float", 0.01)
    data = bytearray(path.read_bytes())
    data[100] ^= 1
    corrupt = tmp_path / "corrupt.ck"
    corrupt.write_bytes(bytes(data))
    with pytest.raises(sphere.Error, match=re.escape(f"sphere: checkpoint '{corrupt}': corrupt: checksum mismatch")):
        sphere.read_checkpoint(corrupt)
    text = tmp_path / "text.ck"
    text.write_text("not a checkpoint")
    with pytest.raises(sphere.Error, match="not a sphere checkpoint"):
        sphere.read_checkpoint(text, precision="float")
