"""One make per case output folder (issue 17, item 8): a second `make case=X` while the first runs
fails at once, saying who holds out/X/, instead of solving into the same files (before the lock one
drew 35 frames of the other's run in progress, another read '\\0\\0\\0' from history.csv)."""
import os
import signal
import subprocess

import pytest

from e2e_support import new_case_folder  # noqa: E402
from make_tree import make, make_tree, start_make, wait_for_steps

NAME = "lockcase"


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    work, _ = new_case_folder(tmp_path_factory, "lock", "unused")
    return make_tree(work, NAME)


def test_a_second_make_of_the_same_case_fails_at_once_naming_the_first(tree):
    out = tree / "out" / NAME
    first = start_make(tree, NAME, f"out/{NAME}/.solved")
    try:
        wait_for_steps(out, first)
        history_before = (out / "history.csv").stat().st_ino
        second = start_make(tree, NAME, f"out/{NAME}/.solved")
        try:
            _, err = second.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(second.pid, signal.SIGKILL)
            raise AssertionError("the second make ran instead of stopping at the lock")
        assert second.returncode != 0
        assert f"error: out/{NAME}/ is in use by another run (pid " in err, err
        assert f"make out/{NAME}/.solved case={NAME} config={NAME}, since " in err
        assert "give LOCK_WAIT=<seconds> to wait" in err
        assert first.poll() is None                                     # the first goes on
        assert (out / "history.csv").stat().st_ino == history_before     # its files untouched
        # Other goals of other folders, and the unlocked ones, still run: `check` reads only.
        assert make(tree, NAME, "check").returncode == 0
    finally:
        os.killpg(first.pid, signal.SIGTERM)
        first.communicate(timeout=120)
    assert (out / "checkpoint.bin").exists()


def test_the_lock_is_free_again_when_make_ends(tree):
    out = tree / "out" / NAME
    result = make(tree, NAME, f"out/{NAME}/mesh-parameters.json")
    assert result.returncode == 0, result.stderr
    assert (out / ".lock").exists()
    # The inner make's check that it holds the lock reads fd 9 and writes nothing: `flock -n 9 true`
    # (a command after the number) locked, and so created, a file named "9" in the repository's root.
    assert not (tree / "9").exists()


def test_pd_case_lock_in_the_environment_does_not_skip_the_lock(tree):
    """PD_CASE_LOCK=1 is the Makefile's own mark of the make it starts under the lock; set in the
    environment of a make run by hand it skipped the lock, and two solvers ran on one folder
    (issue 36 probe). Now that make checks it holds the lock, and stops."""
    out = tree / "out" / NAME
    first = start_make(tree, NAME, f"out/{NAME}/.solved")
    try:
        wait_for_steps(out, first)
        second = start_make(tree, NAME, f"out/{NAME}/.solved", env={"PD_CASE_LOCK": "1"})
        _, err = second.communicate(timeout=60)
        assert second.returncode != 0
        assert "PD_CASE_LOCK is this Makefile's own" in err, err
        assert first.poll() is None
    finally:
        os.killpg(first.pid, signal.SIGTERM)
        first.communicate(timeout=120)
