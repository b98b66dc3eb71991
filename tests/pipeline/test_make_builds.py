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
