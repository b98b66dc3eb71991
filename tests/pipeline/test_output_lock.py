"""common/output_lock.py: the one lock of an output folder, shared with make's flock(1)."""
import os
import subprocess
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from common.output_lock import FolderInUse, exit_code, output_lock  # noqa: E402


def test_a_second_holder_is_refused_naming_the_first_and_the_lock_goes_with_the_first(tmp_path):
    with output_lock(str(tmp_path), "bench one"):
        with pytest.raises(FolderInUse, match=rf"{tmp_path}/ is in use by another run \(pid {os.getpid()}, "
                                              r"bench one, since \d\d:\d\d:\d\d\)"):
            with output_lock(str(tmp_path), "bench two"):
                pass
        # make's own test, flock(1) with no wait, is refused too.
        assert subprocess.run(["flock", "-n", str(tmp_path / ".lock"), "true"]).returncode == 1
    assert subprocess.run(["flock", "-n", str(tmp_path / ".lock"), "true"]).returncode == 0
    with output_lock(str(tmp_path), "bench two"):
        assert "bench two" in (tmp_path / ".lock").read_text()


def test_wait_takes_the_lock_when_the_holder_ends(tmp_path):
    holder = subprocess.Popen(["flock", str(tmp_path / ".lock"), "sleep", "1"])
    time.sleep(0.3)
    begin = time.monotonic()
    with output_lock(str(tmp_path), "waiter", wait=30):
        assert 0.2 < time.monotonic() - begin < 20
    holder.wait()


def test_a_lock_file_that_is_a_link_is_refused(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    out = tmp_path / "out"
    out.mkdir()
    os.symlink(victim, out / ".lock")
    with pytest.raises(OSError):
        with output_lock(str(out), "x"):
            pass
    assert victim.read_text() == "precious\n"


def test_a_command_line_says_the_folder_is_in_use_with_exit_75_and_no_traceback(tmp_path, capsys):
    def main():
        with output_lock(str(tmp_path), "inner"):
            pass
    with output_lock(str(tmp_path), "outer"):
        assert exit_code(main) == 75
    assert "is in use by another run" in capsys.readouterr().err
    assert exit_code(lambda: 3) == 3 and exit_code(lambda: None) == 0
