"""The Makefile's case= and config= are names of what is under cases/, checked before anything
expands them: a command in the name never runs, and a path never leaves the repository.

These run the real make (parse-time checks only: no stage runs) with a marker file or a victim
folder in a temporary directory, and assert that nothing happened and make said why."""
import os
import shutil
import subprocess

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def make(*args, threads=None):
    """make in ROOT; threads: OMP_NUM_THREADS for it (None: unset, whatever the runner has)."""
    env = {k: v for k, v in os.environ.items() if k not in ("case", "config", "MAKEFLAGS", "MAKELEVEL", "OMP_NUM_THREADS")}
    if threads is not None:
        env["OMP_NUM_THREADS"] = str(threads)
    return subprocess.run(["make", "--no-print-directory", "-C", ROOT, *args], env=env,
                          capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("name", [
    "a`touch$${IFS}{marker}`",          # a shell command substitution in the recipe
    "a$$(touch$${IFS}{marker})",
    "$(shell touch {marker})",           # a make function, expanded wherever $(case) is
    "a;touch {marker}",
])
@pytest.mark.parametrize("variable", ["case", "config"])
def test_a_command_in_the_name_never_runs(tmp_path, variable, name):
    marker = tmp_path / "pwned"
    value = name.replace("{marker}", str(marker))
    extra = ["case=membrane"] if variable == "config" else []
    result = make("clean-case", *extra, f"{variable}={value}")
    assert result.returncode != 0
    assert f"is not a {variable} name" in result.stderr, result.stderr
    assert "letters, digits, '_' and '-' only" in result.stderr
    assert not marker.exists()


def test_clean_case_never_deletes_outside_out(tmp_path):
    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "keep.txt").write_text("precious\n")
    relative = os.path.relpath(victim, os.path.join(ROOT, "out"))   # out/../../…/victim
    assert relative.startswith("..")
    result = make("clean-case", f"case={relative}")
    assert result.returncode != 0
    assert f"case='{relative}' is not a case name" in result.stderr, result.stderr
    assert (victim / "keep.txt").read_text() == "precious\n"


def test_a_case_path_never_writes_outside_out(tmp_path):
    # cases/<rel> and out/<rel> are the same folder outside the repository: before the check,
    # make wrote mesh-parameters.json into it.
    folder = tmp_path / "x"
    folder.mkdir()
    shutil.copy(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"), folder / "x.yaml")
    relative = os.path.relpath(folder, os.path.join(ROOT, "cases"))
    result = make(f"case={relative}", f"out/{relative}/mesh-parameters.json")
    assert result.returncode != 0
    assert "is not a case name" in result.stderr, result.stderr
    assert sorted(p.name for p in folder.iterdir()) == ["x.yaml"]


def test_a_missing_case_or_config_is_named():
    result = make("clean-case", "case=no_such_case")
    assert result.returncode != 0
    assert "case=no_such_case: no folder cases/no_such_case/; the cases are: " in result.stderr
    assert "membrane" in result.stderr
    result = make("clean-case", "case=membrane", "config=no_such_config")
    assert result.returncode != 0
    assert "no file cases/membrane/no_such_config.yaml; the configs of membrane are: adaptive membrane" \
        in result.stderr, result.stderr


def test_valid_names_pass_and_are_quoted():
    result = make("-n", "clean-case", "case=membrane", "config=adaptive")
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "rm -rf -- 'out/membrane-adaptive'"
    result = make("-n", "clean-case")   # the default case
    assert result.returncode == 0 and result.stdout.strip() == "rm -rf -- 'out/membrane'"


@pytest.mark.parametrize("value", [
    "a`touch$${IFS}{marker}`",
    "$(shell touch {marker})",
    "1;touch {marker}",
    "x", "0", "-2", "2.5",
])
def test_ranks_is_a_number_of_mpi_ranks(tmp_path, value):
    marker = tmp_path / "pwned"
    result = make("clean-case", "case=membrane", "RANKS=" + value.replace("{marker}", str(marker)))
    assert result.returncode != 0
    assert "is not a number of MPI ranks" in result.stderr, result.stderr
    assert not marker.exists()


def test_ranks_puts_the_solver_under_mpiexec():
    def solve_line(*args):
        # -B: the recipe is printed even when out/membrane/ is up to date (a user who ran the case
        # before `make test`)
        result = make("-n", "-B", "case=membrane", *args, "out/membrane/.solved")
        return [line for line in result.stdout.splitlines() if "exec " in line and "--restart" not in line]
    assert not any("mpiexec" in line for line in solve_line())
    assert not any("mpiexec" in line for line in solve_line("RANKS=1"))
    assert any("exec sh pipeline/run-ranks.sh mpiexec --oversubscribe -np 3 -x OMP_NUM_THREADS=" in line and "'build/solver/pdsolve'" in line
               for line in solve_line("RANKS=3"))


@pytest.mark.parametrize("ranks", [2, 3])
def test_ranks_share_the_cores_unless_omp_num_threads_is_set(ranks):
    """R ranks with OMP_NUM_THREADS unset get cores // R threads each (at least 1), not all the cores
    each; a user's OMP_NUM_THREADS is left to mpiexec's environment as it is."""
    def solve_lines(threads):
        result = make("-n", "-B", "case=membrane", f"RANKS={ranks}", "out/membrane/.solved", threads=threads)
        return [line for line in result.stdout.splitlines() if line.strip().startswith("exec ")]
    share = max(1, len(os.sched_getaffinity(0)) // ranks)  # what nproc counts
    lines = solve_lines(None)
    assert len(lines) == 2, lines  # the fresh solve and the resume
    assert all(f"mpiexec --oversubscribe -np {ranks} -x OMP_NUM_THREADS={share} 'build/solver/pdsolve'" in line
               for line in lines), lines
    lines = solve_lines(2)
    assert len(lines) == 2 and all(f"mpiexec --oversubscribe -np {ranks} 'build/solver/pdsolve'" in line
                                   for line in lines), lines


def test_ranks_resumes_a_checkpoint_under_mpiexec_too():
    """A checkpoint of a decomposed run restarts on any rank count (issue 15): the resume branch of
    the solve recipe runs under the same mpiexec as a fresh solve."""
    result = make("-n", "-B", "case=membrane", "RANKS=3", "out/membrane/.solved")
    resume = [line for line in result.stdout.splitlines() if line.strip().startswith("exec ") and "--restart" in line]
    assert resume and all("exec sh pipeline/run-ranks.sh mpiexec --oversubscribe -np 3 " in line and "'build/solver/pdsolve'" in line
                          for line in resume), resume
    serial = make("-n", "-B", "case=membrane", "out/membrane/.solved")
    assert not any("mpiexec" in line for line in serial.stdout.splitlines() if "--restart" in line)


def test_make_help_lists_the_commands():
    """`make help` prints the list at the top of the Makefile (it was "No rule to make target
    'help'", then the case lock's error)."""
    result = make("help")
    assert result.returncode == 0, result.stderr
    lines = [line.strip() for line in result.stdout.splitlines()]
    assert lines[0].startswith("make case=membrane ")
    assert any(line.startswith("make case=X RANKS=R ") for line in lines)
    assert any(line.startswith("make test ") for line in lines)
    assert not any(line.startswith("#") for line in lines) and result.stderr == ""


# Issue 36, item 4: every other make variable that reaches a shell is checked, or not settable.
@pytest.mark.parametrize("setting", [
    "LOCK_WAIT=0' -E 75 /x true; touch {marker}; echo '",
    "JOBS=2; touch {marker}",
    "FUZZ_SECONDS=$$(touch {marker})",
    "BENCH_SIDES=40 `touch {marker}`",
    "ACCURACY_ARGS=--quick; touch {marker}",
    "IMPLICIT_ARGS=--loads blow && touch {marker}",
    "SOLVER=x';touch {marker};'",
])
def test_a_command_in_a_setting_never_runs(tmp_path, setting):
    marker = tmp_path / "pwned"
    name = setting.split("=", 1)[0]
    result = make("check", "case=membrane", setting.replace("{marker}", str(marker)))
    assert result.returncode != 0
    assert f"{name}='" in result.stderr, result.stderr
    assert not marker.exists()


@pytest.mark.parametrize("variable", ["OUT", "PY", "MPIRUN", "CHECKPOINT", "MAKE", "SHELL"])
def test_internal_variables_are_not_settable_from_the_command_line(tmp_path, variable):
    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "keep.txt").write_text("precious\n")
    result = make("clean-case", "case=membrane", f"{variable}={victim}")
    assert result.returncode != 0
    assert f"{variable} is set by this Makefile, not on the command line" in result.stderr, result.stderr
    assert (victim / "keep.txt").read_text() == "precious\n"


def test_a_goal_with_shell_characters_never_runs(tmp_path):
    marker = tmp_path / "pwned"
    result = make(f"x';touch {marker};'", "case=membrane")
    assert result.returncode != 0
    assert "holds a character a shell would read" in result.stderr, result.stderr
    assert not marker.exists()


@pytest.mark.parametrize("value", ["..", ".", "1.2.3"])
def test_a_lock_wait_that_is_no_number_is_refused(value):
    """`LOCK_WAIT=..` passed the character check; flock then failed and make blamed a stale holder."""
    result = make("-n", "clean-case", "case=membrane", f"LOCK_WAIT={value}")
    assert result.returncode != 0
    assert f"LOCK_WAIT='{value}' is not a number of seconds" in result.stderr, result.stderr


def test_good_settings_pass():
    result = make("-n", "clean-case", "case=membrane", "LOCK_WAIT=1.5", "JOBS=3", "BENCH_SIDES=40 100",
                  "ACCURACY_ARGS=--quick --coarsen 4", "SOLVER=build/solver/pdsolve")
    assert result.returncode == 0, result.stderr
    assert "rm -rf -- 'out/membrane'" in result.stdout


def test_ranks_beyond_the_machine_are_refused():
    result = make("-n", "case=membrane", "RANKS=1000")
    assert result.returncode != 0
    assert "RANKS=1000 is more than 4 ranks per core on this machine" in result.stderr, result.stderr
    assert f"give at most RANKS={4 * len(os.sched_getaffinity(0))}," in result.stderr   # nproc
    huge = make("-n", "case=membrane", "RANKS=" + "9" * 40)
    assert huge.returncode != 0 and "more than 4 ranks per core" in huge.stderr
