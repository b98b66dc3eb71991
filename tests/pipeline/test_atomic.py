"""common/atomic.py, the one atomic-file writer: content, plain-open() mode, nothing left behind."""
import os
import stat

import pytest

from common.atomic import atomic_path, write_atomically


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


# -- signals and dead writers (issue 17, item 7) --------------------------------------------------
import signal  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

WRITER = """
import time
from common.atomic import atomic_path
with atomic_path({target!r}) as tmp:
    with open(tmp, "w") as stream:
        stream.write("half of a 90 MB node file")
    print("writing", flush=True)
    time.sleep(60)
"""


def start_writer(target):
    process = subprocess.Popen([sys.executable, "-c", WRITER.format(target=str(target))], cwd=ROOT,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert process.stdout.readline() == "writing\n"
    return process


def test_sigterm_while_writing_removes_the_temporary_file(tmp_path):
    target = tmp_path / "nodes.vtu"
    process = start_writer(target)
    assert len(list(tmp_path.iterdir())) == 1   # the temporary file, under way
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=30)
    assert process.returncode == 128 + signal.SIGTERM, err
    assert "Traceback" not in err
    assert list(tmp_path.iterdir()) == []       # neither the file nor its temporary


def test_a_killed_writers_temporary_file_goes_with_the_next_write(tmp_path):
    target = tmp_path / "nodes.vtu"
    process = start_writer(target)
    process.kill()                               # kill -9: no handler runs
    process.wait(timeout=30)
    left = [p.name for p in tmp_path.iterdir()]
    assert len(left) == 1 and left[0].startswith(f".tmp-{process.pid}-") and left[0].endswith("-nodes.vtu")
    (tmp_path / ".tmp-1-keep-other.vtu").write_text("another file's temporary")
    write_atomically(str(target), "new")
    assert sorted(p.name for p in tmp_path.iterdir()) == [".tmp-1-keep-other.vtu", "nodes.vtu"]
    assert target.read_text() == "new"


def test_a_running_writers_temporary_file_is_left_alone(tmp_path):
    target = tmp_path / "nodes.vtu"
    process = start_writer(target)
    try:
        write_atomically(str(target), "other writer")
        assert len([p for p in tmp_path.iterdir() if p.name.startswith(f".tmp-{process.pid}-")]) == 1
    finally:
        process.kill()
        process.wait(timeout=30)


def test_the_callers_sigterm_handler_is_restored(tmp_path):
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
    with atomic_path(str(tmp_path / "a")) as tmp:
        assert signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL
        with atomic_path(str(tmp_path / "b")) as inner:
            open(inner, "w").close()
        assert signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL
        open(tmp, "w").close()
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
