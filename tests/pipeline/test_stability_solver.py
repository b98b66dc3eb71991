"""The stable step that preprocess checks and plans with is the solver's own (pipeline/solver_physics.py,
`pdsolve --physics`): asked on a temporary copy of the cloud and the resolved case before anything is
written, it equals `pdsolve --stable-dt` on the case.json and nodes.vtu preprocess then writes, bit for
bit, on every shipped case (cases/*/*.yaml, variants included) and with each partial-volume rule; the
messages quote it; and a missing solver is a clear error that leaves nothing written."""
import glob
import json
import os
import subprocess

import pytest

from pipeline import run as driver
from pipeline import solver_physics
from pipeline.case import load_case
from pipeline.resolve import resolve
from pipeline.stability import check_discretized_case
from preprocess.node_file import read_node_file

from common.paths import REPOSITORY as ROOT
from minimal_case import PMMA_PLATE, lattice_cloud

CASES = sorted(glob.glob(os.path.join(ROOT, "cases", "*", "*.yaml")))


def compare(yaml, case_dir, tmp_path, pdsolve):
    name = os.path.basename(case_dir)
    given = [p for p in (os.path.join(case_dir, name + ext) for ext in (".unv", ".msh")) if os.path.exists(p)]
    mesh = given[0] if given else str(tmp_path / "mesh.msh")
    if not given:
        assert driver.main(["mesh", yaml, os.path.join(case_dir, name + ".geo"), mesh]) == 0
    assert driver.main(["preprocess", yaml, mesh, str(tmp_path)]) == 0
    with open(tmp_path / "case.json", encoding="utf-8") as stream:
        resolved = json.load(stream)
    # What preprocess asked (the same resolved case and cloud, in a temporary folder) ...
    asked = solver_physics.physics_of_cloud(resolved, read_node_file(str(tmp_path / "nodes.vtu")), solver=pdsolve)
    out = subprocess.run([pdsolve, str(tmp_path / "case.json"), "--stable-dt"], check=True,
                         capture_output=True, text=True).stdout
    solver = json.loads(out)
    # ... is what the solver computes for the run of the written files.
    assert asked["safety_factor"] == solver["safety_factor"] == resolved["time"]["safety_factor"]
    assert asked["stable"] == solver["stable"]
    assert [b["name"] for b in asked["blocks"]] == [b["name"] for b in resolved["blocks"]]


@pytest.mark.parametrize("yaml", CASES, ids=lambda p: os.path.relpath(p, os.path.join(ROOT, "cases")))
def test_preprocess_checks_the_solvers_eq_2_5(yaml, tmp_path, pdsolve, monkeypatch):
    # FORCE=1: the full beam_3d's work plan (at least 2.7 h) stops preprocess otherwise; only its
    # node file and case.json are needed here, the run is never made
    monkeypatch.setenv("FORCE", "1")
    monkeypatch.setenv("PDSOLVE", pdsolve)
    compare(yaml, os.path.dirname(yaml), tmp_path, pdsolve)


@pytest.mark.parametrize("rule", ["lammps", "hhb"])
def test_with_partial_volumes_too(rule, tmp_path, pdsolve, monkeypatch):
    """No shipped case uses ν; the membrane with each rule (hhb also widens the family)."""
    monkeypatch.setenv("PDSOLVE", pdsolve)
    case_dir = os.path.join(ROOT, "cases", "membrane")
    with open(os.path.join(case_dir, "membrane.yaml"), encoding="utf-8") as stream:
        text = stream.read()
    assert text.count("\ndiscretization:\n") == 1
    yaml = tmp_path / "membrane.yaml"
    yaml.write_text(text.replace("\ndiscretization:\n", f"\ndiscretization:\n  partial_volume: {rule}\n"))
    compare(str(yaml), case_dir, tmp_path, pdsolve)


def plate(tmp_path, time_keys):
    path = tmp_path / "plate.yaml"
    path.write_text(PMMA_PLATE + time_keys)
    case = load_case(str(path))
    cloud = lattice_cloud()
    return case, resolve(case, node_sets=[], grid_spacing=cloud.grid_spacing, nodes_file="nodes.vtu"), cloud


def test_the_warning_quotes_the_solvers_step_and_node(tmp_path, pdsolve, monkeypatch):
    """A fixed time.dt above the stable step: the warning's step and node are --physics's."""
    monkeypatch.setenv("PDSOLVE", pdsolve)
    case, resolved, cloud = plate(tmp_path, "  dt: 1.0e-5\n")
    answer = solver_physics.physics_of_cloud(resolved, cloud)
    (warning,) = check_discretized_case(case, resolved, cloud)
    assert f"a stable step of {answer['stable']:.3g} s at node {answer['node']} " in warning
    assert 0 <= answer["node"] < len(cloud.points) and 0.0 < answer["stable"] < 1.0e-5


def test_a_missing_solver_is_a_clear_error_and_nothing_is_written(tmp_path, monkeypatch, capsys):
    case_dir = os.path.join(ROOT, "cases", "membrane")
    mesh = str(tmp_path / "mesh.msh")
    yaml = os.path.join(case_dir, "membrane.yaml")
    assert driver.main(["mesh", yaml, os.path.join(case_dir, "membrane.geo"), mesh]) == 0
    missing = str(tmp_path / "no" / "pdsolve")
    monkeypatch.setenv("PDSOLVE", missing)
    case, resolved, cloud = plate(tmp_path, "")
    with pytest.raises(solver_physics.SolverError, match=r"the solver .*/no/pdsolve is missing; the stable time "
                                                         r"step and the work plan are computed by it: build it with "
                                                         r"`make solver`"):
        check_discretized_case(case, resolved, cloud)
    # The stage: exit 2 with that message, and no case.json or nodes.vtu.
    out = tmp_path / "out"
    capsys.readouterr()
    assert driver.main(["preprocess", yaml, mesh, str(out)]) == 2
    assert f"error: the solver {missing} is missing" in capsys.readouterr().err
    assert not os.path.exists(out / "case.json") and not os.path.exists(out / "nodes.vtu")
