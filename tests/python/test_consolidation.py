"""sphere.consolidate against the C++ consolidation example: the same printed numbers and the
same final checkpoint, to the last bit."""

import sphere


def test_consolidate_equals_the_cpp_example(cpp_consolidation, precision, tmp_path, capsys):
    path, printed = cpp_consolidation(precision, 0.01)
    result = sphere.consolidate(particles=150, duration=0.01, precision=precision, checkpoint=tmp_path / "py.ck")
    lines = capsys.readouterr().out.splitlines()
    expected = [line for line in printed.splitlines() if not line.startswith("output in")]
    assert lines == expected
    assert (tmp_path / "py.ck").read_bytes() == path.read_bytes()
    assert result.compression == result.sample_top - result.wall_position
    assert result.simulation.walls().position[5] == result.wall_position
    assert f"{result.porosity:14.6f}" in expected[3]
