"""What every end-to-end test needs: where the repository and the solver are, and a case folder
laid out as the pipeline expects it (work/cases/<name>/), in pytest's temporary directory."""
import os

import pytest

from common.paths import PYTHON as PY, REPOSITORY as ROOT, pdsolve  # noqa: F401  (PY: for the tests' own commands)
from pipeline import stages

# PDSOLVE points the tests at another build (a sanitizer build, a helper's own build folder).
SOLVER = pdsolve()


def new_case_folder(tmp_path_factory, work_name: str, case_name: str):
    """(work, work/cases/<case_name>): a fresh working folder with an empty case folder in it.
    Fails at once with what to do when the solver has not been built."""
    if not os.path.exists(SOLVER):
        pytest.fail(f"{SOLVER} is missing: build it with `make solver` (make test does)")
    work = tmp_path_factory.mktemp(work_name)
    case_dir = work / "cases" / case_name
    case_dir.mkdir(parents=True)
    return work, case_dir


def _run(args):
    import subprocess
    result = subprocess.run(list(args), cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, f"{' '.join(args)} failed:\n{result.stdout}\n{result.stderr}"


def prepare_stages(yaml_path, geo_path, out):
    """The Makefile's first two stages on one case (pipeline/stages.py): mesh, then preprocess into
    out/ (case.json and the node file); a failing stage raises its error, naming the file."""
    stages.mesh(str(yaml_path), str(geo_path), str(out / "mesh.msh"))
    stages.preprocess(str(yaml_path), str(out / "mesh.msh"), str(out), solver=SOLVER)


def run_stages(yaml_path, geo_path, out):
    """The Makefile's stages on one case, in order: mesh, preprocess, solve, postprocess; each must
    succeed (a failing solve shows its output)."""
    prepare_stages(yaml_path, geo_path, out)
    result = stages.solve(str(out / "case.json"), solver=SOLVER, quiet=True, timeout=600)
    assert result.returncode == 0, f"{' '.join(result.args)} failed:\n{result.stdout}\n{result.stderr}"
    stages.postprocess(str(out))
