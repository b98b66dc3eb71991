"""`make case=X` with no goal, the README's first command, runs the whole pipeline. A `help` rule
placed before `all` in the Makefile once made the locked re-run of make (which passes no goal on)
print the command list and exit 0 without solving anything; no test ran make without a goal."""
import pytest

from e2e_support import new_case_folder  # noqa: E402
from make_tree import make, make_tree

NAME = "goalcase"


# slow: make validate runs `make case=X` with no goal for each of its cases and reads what it wrote.
@pytest.mark.slow
def test_make_with_only_case_runs_every_stage_to_the_figures(tmp_path_factory):
    work, _ = new_case_folder(tmp_path_factory, "goal", "unused")
    tree = make_tree(work, NAME, end=0.02)  # 0.02 s of simulated time: a short solve
    out = tree / "out" / NAME
    result = make(tree, NAME)  # no goal: make case=goalcase
    assert result.returncode == 0, result.stdout + result.stderr
    assert "make help" not in result.stdout, "the command list instead of the run:\n" + result.stdout
    assert f"results in out/{NAME}/" in result.stdout, result.stdout
    for produced in (".solved", "history.csv", "frames.pvd", "figures/.done"):
        assert (out / produced).exists(), produced
