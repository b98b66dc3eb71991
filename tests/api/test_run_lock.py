"""peridyn's Case.run takes the output folder's lock, the one make takes (issue 36, item 5): before,
two runs into one folder both returned OK reporting the second run's results, and a Case.run beside
`make case=membrane` wrote NUL bytes into history.csv."""
import os
import signal
import subprocess
import sys
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

import peridyn  # noqa: E402

SOLVER = os.environ.get("PDSOLVE", os.path.join(ROOT, "build", "solver", "pdsolve"))


def small_case(end=1.0e-4):
    case = peridyn.load(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"))
    case["discretization.dx"] = 2.5e-3
    case["node_sets.clamped.layer"] = 7.5e-3
    case["time.end"] = end
    case["output.every_time"] = end / 4
    case["figures.times"] = None
    return case


def test_a_run_into_a_folder_make_holds_is_refused_before_any_work(tmp_path):
    out = tmp_path / "held"
    out.mkdir()
    (out / ".lock").write_text("pid 1, make all case=held config=held, since 12:00:00\n")
    # flock(1) on the file, as the Makefile's pd-case-lock rule holds it while make runs.
    holder = subprocess.Popen(["flock", str(out / ".lock"), "sleep", "60"])
    try:
        deadline = time.monotonic() + 10
        while subprocess.run(["flock", "-n", str(out / ".lock"), "true"]).returncode == 0:
            assert time.monotonic() < deadline, "flock(1) did not take the lock"
            time.sleep(0.05)
        with pytest.raises(peridyn.RunError, match=r"held/ is in use by another run \(pid 1, make all case=held"):
            small_case().run(str(out), threads=1)
        assert sorted(os.listdir(out)) == [".lock"]      # nothing written: not even the .yaml
    finally:
        holder.kill()
        holder.wait()


def test_the_folder_stays_locked_while_case_run_solves(tmp_path):
    if not os.path.isfile(SOLVER):
        pytest.fail(f"{SOLVER} is missing: build it with `make solver`")
    out = tmp_path / "busy"
    script = (f"import sys; sys.path.insert(0, {ROOT!r}); import peridyn\n"
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
