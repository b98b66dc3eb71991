"""pipeline/atomic.py, the one atomic-file writer: content, plain-open() mode, nothing left behind."""
import os
import stat

import pytest

from pipeline.atomic import atomic_path, write_atomically


@pytest.fixture
def umask_022():
    old = os.umask(0o022)
    try:
        yield
    finally:
        os.umask(old)


def mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def test_text_and_bytes_arrive_whole_with_the_mode_of_a_plain_open(tmp_path, umask_022):
    plain = tmp_path / "plain.txt"
    with open(plain, "w") as stream:
        stream.write("x")
    write_atomically(str(tmp_path / "a" / "case.json"), "{\"é\": 1}\n")  # makes the directory too
    write_atomically(str(tmp_path / "nodes.vtu"), b"\x00\x01raw")
    assert (tmp_path / "a" / "case.json").read_text(encoding="utf-8") == "{\"é\": 1}\n"
    assert (tmp_path / "nodes.vtu").read_bytes() == b"\x00\x01raw"
    assert mode(plain) == 0o644
    assert mode(tmp_path / "a" / "case.json") == mode(plain)
    assert mode(tmp_path / "nodes.vtu") == mode(plain)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "nodes.vtu", "plain.txt"]


def test_the_temporary_name_keeps_the_suffix_and_replaces_an_old_file(tmp_path, umask_022):
    target = tmp_path / "energy.png"
    target.write_text("old")
    with atomic_path(str(target)) as tmp:
        assert tmp.endswith("-energy.png") and os.path.dirname(tmp) == str(tmp_path)
        assert target.read_text() == "old"  # untouched until the writer is done
        with open(tmp, "w") as stream:
            stream.write("new")
    assert target.read_text() == "new" and mode(target) == 0o644


def test_an_exception_leaves_no_temporary_file_and_the_old_file_intact(tmp_path, umask_022):
    target = tmp_path / "results.msh"
    target.write_text("old")

    class Boom(Exception):
        pass

    with pytest.raises(Boom):
        with atomic_path(str(target)) as tmp:
            with open(tmp, "w") as stream:
                stream.write("half")
            raise Boom
    with pytest.raises(Boom):
        with atomic_path(str(tmp_path / "removed.txt")) as tmp:
            os.unlink(tmp)  # a writer that removed its file first: still no error but Boom
            raise Boom
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.msh"]
    assert target.read_text() == "old"
