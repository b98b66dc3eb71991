"""What make builds for what (issue 39, item 4): a case needs pdsolve alone; building every test and
benchmark too was about 8 of the first `make case=membrane`'s 10 minutes on a shared machine."""
import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def dry_run(*goals):
    """make -n -B: every recipe the goals would run on a fresh clone, nothing run."""
    env = {k: v for k, v in os.environ.items() if k not in ("case", "config", "MAKEFLAGS", "MAKELEVEL")}
    result = subprocess.run(["make", "--no-print-directory", "-n", "-B", "-C", ROOT, *goals], env=env,
                            capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert result.returncode == 0, result.stderr
    return [line for line in result.stdout.splitlines() if line.startswith("cmake --build build/solver ")]


def test_a_case_builds_pdsolve_alone():
    assert dry_run("case=membrane") == ["cmake --build build/solver -j2 --target pdsolve"]


def test_test_bench_and_validate_build_every_target():
    for goal in ("test", "bench", "validate"):
        builds = dry_run(goal)
        assert "cmake --build build/solver -j2" in builds, (goal, builds)


def test_another_solver_is_never_built_or_touched(tmp_path):
    """SOLVER=<path> (validation's PDSOLVE) is used as it is: its rule was build/solver's, and the
    locked re-run of make does not get make's -o, so `make SOLVER=/usr/bin/touch -o /usr/bin/touch`
    started cmake, whose recipe ends touching $(SOLVER) (issue 36 probe)."""
    other = tmp_path / "pdsolve"
    other.write_text("#!/bin/sh\n")
    os.utime(other, (1_000_000_000, 1_000_000_000))     # older than every source
    assert dry_run("case=membrane", f"SOLVER={other}") == []
    env = {k: v for k, v in os.environ.items() if k not in ("case", "config", "MAKEFLAGS", "MAKELEVEL")}
    built = subprocess.run(["make", "--no-print-directory", "-C", ROOT, "solver", f"SOLVER={other}"], env=env,
                           capture_output=True, text=True, timeout=120)
    assert built.returncode == 0 and "cmake" not in built.stdout, built.stdout + built.stderr
    assert other.stat().st_mtime == 1_000_000_000
    missing = subprocess.run(["make", "--no-print-directory", "-C", ROOT, "solver", f"SOLVER={tmp_path}/none"],
                             env=env, capture_output=True, text=True, timeout=120)
    assert missing.returncode != 0
    assert f"error: SOLVER={tmp_path}/none: no such file; build that solver" in missing.stderr
