"""Signals as batch systems send them, against the real `make case=X` (issue 17, item 4).

`timeout`, CI runners, SLURM and systemd send SIGTERM to the whole process group: the solver gets it
directly and once more forwarded by make. Before run/signals.cpp counted signals within 2 s of the
first as one request, the forwarded copy killed the solver while it wrote its checkpoint (no
checkpoint in 5 of 24 trials). Every trial here must end with a checkpoint that the solver wrote
whole (its checksum is checked by a restart) and run.log saying why it stopped.
"""
import os
import shutil
import signal
import struct
import subprocess
import time

import pytest

from e2e_support import SOLVER, new_case_folder  # noqa: E402
from make_tree import default_sigint, make_tree, start_make, wait_for_steps

NAME = "sig"


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    work, _ = new_case_folder(tmp_path_factory, "signals", "unused")
    return make_tree(work, NAME)


def fresh(tree):
    """Remove what a previous trial left, so that make starts a fresh solve (not a resume)."""
    out = tree / "out" / NAME
    for name in ("checkpoint.bin", "history.csv", "run.log", ".solved"):
        (out / name).unlink(missing_ok=True)
    return out


def assert_whole_checkpoint(out, signal_name):
    checkpoint = out / "checkpoint.bin"
    assert checkpoint.exists(), (out / "run.log").read_text()[-1500:]
    data = checkpoint.read_bytes()
    assert data[:8] == b"PDCKPT\r\n"
    (payload,) = struct.unpack("<Q", data[16:24])
    assert len(data) == 24 + payload + 8
    assert f"interrupted by {signal_name} after step" in (out / "run.log").read_text()
    # The solver itself accepts it (checksum, case and node-file hashes): restart and stop at once.
    restart = subprocess.Popen([SOLVER, str(out / "case.json"), "--restart", str(checkpoint), "--quiet"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               preexec_fn=default_sigint)
    time.sleep(1.0)
    restart.send_signal(signal.SIGINT)
    _, err = restart.communicate(timeout=120)
    assert restart.returncode == 128 + signal.SIGINT, err
    assert "restart from" in (out / "run.log").read_text()


def finish(process):
    _, err = process.communicate(timeout=120)
    return process.returncode, err


@pytest.mark.parametrize("trial", range(4))
def test_sigterm_to_the_group_writes_a_checkpoint(tree, trial):
    out = fresh(tree)
    process = start_make(tree, NAME, f"out/{NAME}/.solved")
    wait_for_steps(out, process)
    os.killpg(process.pid, signal.SIGTERM)   # make and the solver at once; make forwards a second
    code, err = finish(process)
    assert code != 0
    assert_whole_checkpoint(out, "SIGTERM")
    assert not (out / ".solved").exists()


def test_repeated_sigterm_and_sigint_to_the_group_within_the_window(tree):
    out = fresh(tree)
    process = start_make(tree, NAME, f"out/{NAME}/.solved")
    wait_for_steps(out, process)
    for sig in (signal.SIGTERM, signal.SIGTERM, signal.SIGINT):
        os.killpg(process.pid, sig)
        time.sleep(0.05)
    finish(process)
    assert_whole_checkpoint(out, "SIGTERM")


def test_timeout_running_make_writes_a_checkpoint(tree):
    """timeout(1) runs make in its own group and sends SIGTERM to that whole group when time is up."""
    out = fresh(tree)
    process = start_make(tree, NAME, f"out/{NAME}/.solved", prefix=("timeout", "-s", "TERM", "6"))
    code, err = finish(process)
    assert code == 124, err   # timeout's own code: the time ran out
    assert_whole_checkpoint(out, "SIGTERM")


# A stand-in for the solver under `make case=X RANKS=2`: on SIGTERM it takes 3 s to stop, as a
# rank in a long quasi-static load step finishes it before it writes its checkpoint, then leaves a
# mark per rank. Its pid is in started.N, for the clean-up; it gives up by itself after 60 s. (POSIX
# sh runs the trap once the 0.1 s sleep under way has ended.)
SLOW_STOP = """#!/bin/sh
folder=$(dirname "$1")
trap 'sleep 3; echo stopped > "$folder/stopped.$OMPI_COMM_WORLD_RANK"; exit 143' TERM
echo $$ > "$folder/started.$OMPI_COMM_WORLD_RANK"
n=0
while [ $n -lt 600 ]; do sleep 0.1; n=$((n + 1)); done
"""

MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}
needs_mpiexec = pytest.mark.skipif(shutil.which("mpiexec") is None,
                                   reason="no mpiexec (openmpi-bin: pipeline/install-deps.sh)")


def start_ranked_make(tree, *extra):
    return start_make(tree, NAME, f"out/{NAME}/.solved", "RANKS=2", *extra, env=MPI_ENV)


@pytest.fixture
def ranks_killed_after(tree):
    """mpiexec runs in a session of its own (pipeline/run-ranks.sh): a failing test's killpg of make
    does not reach it, so whatever of the run is left is killed here (the stand-in's pids, and every
    solver working on this tree's case)."""
    yield
    out = tree / "out" / NAME
    for started in out.glob("started.*"):
        try:
            os.kill(int(started.read_text()), signal.SIGKILL)
        except (ValueError, ProcessLookupError):
            pass
    subprocess.run(["pkill", "-KILL", "-f", str(out / "case.json")], check=False)


@needs_mpiexec
def test_under_mpiexec_the_ranks_may_finish_their_step_before_they_stop(tree, tmp_path, ranks_killed_after):
    """Open MPI's mpiexec does not pass a SIGTERM on: it stops the job itself, SIGCONT, SIGTERM 1 s
    later, SIGKILL 1 s after that, and a second signal (make passes one on) makes it exit at once and
    leave the ranks running. A 2-rank quasi_static run stopped so inside a load step of tens of
    seconds wrote no checkpoint and lost everything. The Makefile runs mpiexec through
    pipeline/run-ranks.sh, which signals the ranks themselves: here each takes 3 s to stop, and both
    do (with mpiexec alone neither got the signal: checked)."""
    out = fresh(tree)
    for stale in list(out.glob("started.*")) + list(out.glob("stopped.*")):
        stale.unlink()
    solver = tmp_path / "slow_stop.sh"
    solver.write_text(SLOW_STOP)
    solver.chmod(0o755)
    process = start_ranked_make(tree, f"SOLVER={solver}")
    deadline = time.monotonic() + 60
    while not ((out / "started.0").exists() and (out / "started.1").exists()):
        if process.poll() is not None or time.monotonic() > deadline:
            os.killpg(process.pid, signal.SIGKILL)
            pytest.fail("the stand-in ranks did not start: " + process.communicate(timeout=30)[1])
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGTERM)
    code, err = finish(process)
    assert code != 0
    assert (out / "stopped.0").exists() and (out / "stopped.1").exists(), err
    assert not (out / ".solved").exists()


@needs_mpiexec
def test_ctrl_c_to_a_two_rank_make_writes_a_checkpoint(tree, ranks_killed_after):
    """The real solver on 2 ranks, SIGINT to make's process group as a terminal's Ctrl-C sends it:
    the ranks get it from pipeline/run-ranks.sh as it came, stop after the same step and rank 0
    writes a whole checkpoint (which the serial solver then accepts)."""
    out = fresh(tree)
    process = start_ranked_make(tree)
    wait_for_steps(out, process)
    os.killpg(process.pid, signal.SIGINT)
    code, err = finish(process)
    assert code != 0
    assert "2 MPI ranks" in (out / "run.log").read_text()
    assert_whole_checkpoint(out, "SIGINT")
    assert not (out / ".solved").exists()


# Issue 36, items 6 and 7: a supervisor's `kill <make's pid>` (SIGTERM to make alone, not its group)
# orphaned the solver: flock(1) stood between the two makes and died of it, the run went on with the
# lock held and no checkpoint. And after a SIGTERM to the group, make returned 1-2 s before its
# solver had written the checkpoint (flock again), so a batch system that kills what is left when
# the job script ends lost it. Now make returns only when every process of the run is gone.

def solver_pids(out):
    """pids of the solvers (not zombies) whose command line names this run's case.json (make gives
    it relative to the tree: out/<case>/case.json)."""
    wanted = f"{out.parent.name}/{out.name}/case.json".encode()
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/cmdline", "rb") as stream:
                cmdline = stream.read().split(b"\0")
            with open(f"/proc/{entry}/stat", "rb") as stream:
                state = stream.read().rsplit(b")", 1)[1].split()[0]
        except OSError:
            continue
        if os.path.basename(cmdline[0]) == b"pdsolve" and any(arg.endswith(wanted) for arg in cmdline) \
                and state != b"Z":
            pids.append(int(entry))
    return pids


def lock_is_free(out):
    """True if this process can take out/<case>/.lock at once (what the next make would do)."""
    import fcntl
    with open(out / ".lock", "a") as stream:
        try:
            fcntl.flock(stream, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return False
        fcntl.flock(stream, fcntl.LOCK_UN)
        return True


def test_sigterm_to_makes_pid_alone_writes_a_checkpoint_and_leaves_nothing_running(tree):
    out = fresh(tree)
    process = start_make(tree, NAME, f"out/{NAME}/.solved")
    wait_for_steps(out, process)
    solvers = solver_pids(out)
    assert solvers, "no solver process found"
    try:
        os.kill(process.pid, signal.SIGTERM)       # `kill <pid>`: make alone, not its group
        code, err = finish(process)
        assert code != 0
        assert solver_pids(out) == [], "the solver runs on after make returned"
        assert lock_is_free(out)
        assert_whole_checkpoint(out, "SIGTERM")
        assert "checkpoint written to" in err      # what make's run prints as it ends says so
    finally:
        for pid in solvers:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


@pytest.mark.parametrize("to_group", [False, True], ids=["make-alone", "group"])
def test_make_returns_only_after_its_solver_has_stopped(tree, tmp_path, to_group):
    out = fresh(tree)
    # SLOW_STOP alone, not under mpiexec: its marks are started. and stopped. (no rank number).
    for mark in ("started.", "stopped."):
        (out / mark).unlink(missing_ok=True)
    solver = tmp_path / "slow_stop.sh"
    solver.write_text(SLOW_STOP)
    solver.chmod(0o755)
    process = start_make(tree, NAME, f"out/{NAME}/.solved", f"SOLVER={solver}")
    deadline = time.monotonic() + 60
    while not (out / "started.").exists():
        if process.poll() is not None or time.monotonic() > deadline:
            os.killpg(process.pid, signal.SIGKILL)
            pytest.fail("the stand-in solver did not start: " + process.communicate(timeout=30)[1])
        time.sleep(0.05)
    stand_in = int((out / "started.").read_text())
    try:
        if to_group:
            os.killpg(process.pid, signal.SIGTERM)
        else:
            os.kill(process.pid, signal.SIGTERM)
        finish(process)
        assert (out / "stopped.").exists(), "make returned before its solver had stopped"
        assert lock_is_free(out)                   # an immediate re-run is not refused with 75
    finally:
        try:
            os.kill(stand_in, signal.SIGKILL)
        except ProcessLookupError:
            pass


def mpiexec_pids(out):
    """pids of the mpiexec whose command line names this run's case.json."""
    wanted = f"{out.parent.name}/{out.name}/case.json".encode()
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/cmdline", "rb") as stream:
                    cmdline = stream.read().split(b"\0")
            except OSError:
                continue
            if cmdline and os.path.basename(cmdline[0]) in (b"mpiexec", b"mpirun", b"orterun", b"prterun") \
                    and any(arg.endswith(wanted) for arg in cmdline):
                found.append(int(entry))
    return found


@needs_mpiexec
@pytest.mark.parametrize("target", ["one-rank", "mpiexec"])
def test_sigterm_to_one_rank_or_to_mpiexec_stops_the_run_with_a_checkpoint(tree, target, ranks_killed_after):
    """What a supervisor that knows only one of the run's processes sends (issue 36, item 6): every
    rank stops after the same step, rank 0 writes a whole checkpoint, and nothing of the run is
    left when make returns."""
    out = fresh(tree)
    process = start_ranked_make(tree)
    wait_for_steps(out, process)
    ranks = solver_pids(out)
    launchers = mpiexec_pids(out)
    assert len(ranks) >= 2 and launchers, (ranks, launchers)
    os.kill(ranks[-1] if target == "one-rank" else launchers[0], signal.SIGTERM)
    code, err = finish(process)
    assert code != 0
    assert solver_pids(out) == [] and mpiexec_pids(out) == [], "processes of the run outlived make"
    assert_whole_checkpoint(out, "SIGTERM")


def test_sighup_to_the_group_writes_a_checkpoint(tree):
    """The terminal closed (an ssh session dropped) under `make case=X`: SIGHUP to the whole group
    killed the solver with no checkpoint (issue 36 probe); now it stops the run as SIGTERM does."""
    out = fresh(tree)
    process = start_make(tree, NAME, f"out/{NAME}/.solved")
    wait_for_steps(out, process)
    os.killpg(process.pid, signal.SIGHUP)
    code, err = finish(process)
    assert code != 0
    assert solver_pids(out) == []
    assert_whole_checkpoint(out, "SIGHUP")
