"""What every end-to-end test needs: where the repository and the solver are, and a case folder
laid out as the pipeline expects it (work/cases/<name>/), in pytest's temporary directory."""
import os

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# PDSOLVE points the tests at another build (a sanitizer build, a helper's own build folder).
SOLVER = os.environ.get("PDSOLVE", os.path.join(ROOT, "build", "solver", "pdsolve"))
PY = "/usr/bin/python3"


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
    env = dict(os.environ, PYTHONPATH=ROOT)
    result = subprocess.run(list(args), cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, f"{' '.join(args)} failed:\n{result.stdout}\n{result.stderr}"


def prepare_stages(yaml_path, geo_path, out):
    """The Makefile's first two stages on one case: mesh, then preprocess into out/ (case.json and
    the node file); each must exit 0 (the failure names the stage and shows its output)."""
    _run((PY, "-m", "pipeline.run", "mesh", str(yaml_path), str(geo_path), str(out / "mesh.msh")))
    _run((PY, "-m", "pipeline.run", "preprocess", str(yaml_path), str(out / "mesh.msh"), str(out)))


def run_stages(yaml_path, geo_path, out):
    """The Makefile's stages on one case, in order: mesh, preprocess, solve, postprocess; each must
    exit 0 (the failure names the stage and shows its output)."""
    prepare_stages(yaml_path, geo_path, out)
    _run((SOLVER, str(out / "case.json"), "--quiet"))
    _run((PY, "-m", "postprocess", str(out)))
