"""peridyn's Case.run takes the output folder's lock, the one make takes (issue 36, item 5): before,
two runs into one folder both returned OK reporting the second run's results, and a Case.run beside
`make case=membrane` wrote NUL bytes into history.csv."""
import contextlib
import os
import signal
import subprocess
import sys
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import peridyn
from common.paths import pdsolve

SOLVER = pdsolve()


def small_case(end=1.0e-4):
    case = peridyn.load(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"))
    case["discretization.dx"] = 2.5e-3
    case["node_sets.clamped.layer"] = 7.5e-3
    case["time.end"] = end
    case["output.every_time"] = end / 4
    case["figures.times"] = None
    return case


@contextlib.contextmanager
def held_as_make_holds_it(lock):
    """flock(1) on `lock` for the `with` block, as the Makefile's pd-case-lock rule holds it while
    make runs; its sleep holds the lock too, so the whole group is killed at the end."""
    holder = subprocess.Popen(["flock", str(lock), "sleep", "60"], start_new_session=True)
    try:
        deadline = time.monotonic() + 10
        while subprocess.run(["flock", "-n", str(lock), "true"]).returncode == 0:
            assert time.monotonic() < deadline, "flock(1) did not take the lock"
            time.sleep(0.05)
        yield
    finally:
        os.killpg(holder.pid, signal.SIGKILL)
        holder.wait()


def test_a_run_into_a_folder_make_holds_is_refused_before_any_work(tmp_path):
    out = tmp_path / "held"
    out.mkdir()
    (out / ".lock").write_text("pid 1, make all case=held config=held, since 12:00:00\n")
    with held_as_make_holds_it(out / ".lock"):
        with pytest.raises(peridyn.RunError, match=r"held/ is in use by another run \(pid 1, make all case=held"):
            small_case().run(str(out), threads=1)
        assert sorted(os.listdir(out)) == [".lock"]      # nothing written: not even the .yaml


def test_the_folder_stays_locked_while_case_run_solves(tmp_path):
    if not os.path.isfile(SOLVER):
        pytest.fail(f"{SOLVER} is missing: build it with `make solver`")
    out = tmp_path / "busy"
    script = (f"import peridyn\n"
              f"from tests.api.test_run_lock import small_case\n"
              f"small_case(end=1.0).run({str(out)!r}, threads=1, figures=False)\n")
    first = subprocess.Popen([sys.executable, "-c", script], cwd=ROOT, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while not ((out / "history.csv").exists() and (out / "history.csv").read_text().count("\n") >= 2):
            assert first.poll() is None, first.communicate()
            assert time.monotonic() < deadline, "the first run never started solving"
            time.sleep(0.05)
        # make's flock -w 0 is refused, and so is a second Case.run.
        assert subprocess.run(["flock", "-n", str(out / ".lock"), "true"]).returncode == 1
        with pytest.raises(peridyn.RunError, match=r"busy/ is in use by another run \(pid \d+, peridyn Case.run of "):
            small_case().run(str(out), threads=1)
        # Killed at once (SIGKILL: no clean-up), its solver still holds the lock it was handed.
        os.kill(first.pid, signal.SIGKILL)
        first.wait()
        assert subprocess.run(["flock", "-n", str(out / ".lock"), "true"]).returncode == 1
    finally:
        os.killpg(first.pid, signal.SIGKILL)   # the solver too: it is in the run's session
        first.wait()
    deadline = time.monotonic() + 30
    while subprocess.run(["flock", "-n", str(out / ".lock"), "true"]).returncode != 0:
        assert time.monotonic() < deadline, "the lock outlived the run's processes"
        time.sleep(0.1)


def test_a_mesh_linked_out_of_the_case_folder_is_refused_by_case_run(tmp_path):
    """make's stages refused it, Case.run read it: a .unv linked to a file outside had its first line
    printed in the reader's error (issue 36 probe)."""
    secret = tmp_path / "secret.txt"
    secret.write_text("root:*:20228:0:99999:7:::\n")
    case_dir = tmp_path / "leak"
    case_dir.mkdir()
    (case_dir / "leak.yaml").write_text((open(os.path.join(ROOT, "cases", "membrane", "membrane.yaml")).read()))
    os.symlink(secret, case_dir / "leak.unv")
    case = peridyn.load(str(case_dir / "leak.yaml"))
    with pytest.raises(peridyn.RunError, match=r"leak.unv: leads outside the case folder") as error:
        case.run(str(tmp_path / "out"), figures=False)
    assert "root:" not in str(error.value)
    assert not (tmp_path / "out" / "nodes.vtu").exists()


def test_pdsolve_started_by_hand_into_a_folder_a_run_holds_is_refused(tmp_path):
    """pdsolve locks its output folder itself (io/output_lock.hpp): started by hand beside a make
    solving into the same folder, as its own interrupt message suggests, it wrote NUL bytes into
    history.csv and deleted the other run's frames (issue 36 probe). Here the folder is a finished
    Case.run's, held by flock(1) as make holds it."""
    out = tmp_path / "held"
    small_case().run(str(out), threads=1, figures=False)
    history = (out / "history.csv").read_bytes()
    with held_as_make_holds_it(out / ".lock"):
        env = {k: v for k, v in os.environ.items() if k != "PD_LOCK_FD"}
        result = subprocess.run([SOLVER, str(out / "case.json"), "--quiet"], capture_output=True, text=True,
                                env=env, timeout=60)
        assert result.returncode == 75, result.stderr
        assert f"{out}/ is in use by another run (" in result.stderr
        assert (out / "history.csv").read_bytes() == history           # nothing touched
        # PD_LOCK_FD naming a descriptor of the lock that does not hold it: refused too.
        with open(out / ".lock") as stream:
            handed = subprocess.run([SOLVER, str(out / "case.json"), "--quiet"], capture_output=True, text=True,
                                    env=dict(env, PD_LOCK_FD=str(stream.fileno())), pass_fds=(stream.fileno(),),
                                    timeout=60)
        assert handed.returncode == 75, handed.stderr
    # The lock free: pdsolve by hand takes it, runs, and leaves it free again.
    result = subprocess.run([SOLVER, str(out / "case.json"), "--quiet"], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "pdsolve " in (out / ".lock").read_text()
    assert subprocess.run(["flock", "-n", str(out / ".lock"), "true"]).returncode == 0


def test_a_solver_that_refuses_the_physics_query_is_a_run_error_and_nothing_is_written(tmp_path):
    """Preprocess asks Case.run's own solver for eq. 2.5's step (pdsolve --physics) before it writes:
    a solver that refuses the query stops the run with a RunError naming it, and no case.json."""
    refusing = tmp_path / "pdsolve"
    refusing.write_text("#!/bin/sh\necho 'refused for the test' >&2\nexit 2\n")
    refusing.chmod(0o755)
    out = tmp_path / "out"
    with pytest.raises(peridyn.RunError, match=r"pdsolve --physics .*case\.json failed: refused for the test"):
        small_case().run(str(out), figures=False, solver=str(refusing))
    assert not (out / "case.json").exists() and not (out / "nodes.vtu").exists()
