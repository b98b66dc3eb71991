"""Material models in the case file: a block gives the keys of its model and no other's (the
bond-based PMB fixes Poisson's ratio, so poisson_ratio under model: pmb says so and suggests lps),
LPS's ν range, and the stable step preprocess checks (the solver's, pipeline/solver_physics.py) for LPS."""
import json
import os
import subprocess
import textwrap

import pytest

from pipeline import run as driver
from pipeline.case import CaseError, load_case
from pipeline.solver_physics import physics_of_cloud
from preprocess.node_file import read_node_file

from common.paths import REPOSITORY as ROOT

CASE = """\
dimension: 3
discretization:
  dx: 0.001
materials:
  bar:
    {material}
time:
  end: 1.0e-3
"""


def error_of(tmp_path, material):
    path = tmp_path / "bar.yaml"
    path.write_text(textwrap.dedent(CASE).format(material=material))
    with pytest.raises(CaseError) as info:
        load_case(str(path))
    return str(info.value)


def test_poisson_ratio_under_pmb_says_pmb_fixes_it_and_suggests_lps(tmp_path):
    message = error_of(tmp_path, "{density: 7850, youngs_modulus: 2.1e11, poisson_ratio: 0.29}")
    assert message.startswith(f"{tmp_path / 'bar.yaml'}:6: materials.bar.poisson_ratio: ")
    assert "PMB is bond-based and fixes Poisson's ratio (1/4 in 3D and plane strain, 1/3 in plane stress)" in message
    assert "set model: lps" in message


def test_influence_under_pmb_is_an_error_too(tmp_path):
    message = error_of(tmp_path, "{density: 7850, youngs_modulus: 2.1e11, influence: gaussian}")
    assert "bar.yaml:6: materials.bar.influence: PMB is bond-based" in message
    assert "set model: lps" in message


@pytest.mark.parametrize("nu, words", [(0.5, "must be less than 0.5"), (0.7, "must be less than 0.5"),
                                       (-1.0, "must be greater than -1"), (-1.5, "must be greater than -1")])
def test_poisson_ratio_outside_the_isotropic_range(tmp_path, nu, words):
    message = error_of(tmp_path, f"{{model: lps, density: 7850, youngs_modulus: 2.1e11, poisson_ratio: {nu}}}")
    assert f"bar.yaml:6: materials.bar.poisson_ratio: {words}" in message


def test_lps_needs_poisson_ratio(tmp_path):
    message = error_of(tmp_path, "{model: lps, density: 7850, youngs_modulus: 2.1e11}")
    assert "materials.bar.poisson_ratio: model lps needs poisson_ratio" in message


def test_every_block_uses_one_model_and_one_influence_function(tmp_path):
    path = tmp_path / "two.yaml"
    path.write_text(textwrap.dedent(CASE).format(material="{model: lps, density: 1, youngs_modulus: 1e9, "
                                                 "poisson_ratio: 0.3}")
                    .replace("time:", "  disk: {model: lps, density: 1, youngs_modulus: 1e9, poisson_ratio: 0.3, "
                             "influence: gaussian}\ntime:"))
    with pytest.raises(CaseError, match="every block must use the same influence function"):
        load_case(str(path))
    path.write_text(path.read_text().replace("disk: {model: lps", "disk: {model: pmb").replace(
        ", poisson_ratio: 0.3, influence: gaussian}", "}"))
    with pytest.raises(CaseError, match="every block must use the same model"):
        load_case(str(path))


LPS = "{model: lps, density: 7850, youngs_modulus: 2.1e11, poisson_ratio: 0.29}"


@pytest.mark.parametrize("integrator", ["quasi_static", "mixed"])
def test_lps_runs_quasi_static_and_mixed_matrix_free(tmp_path, integrator):
    """LPS has no assembled tangent, but its Newton solves run by CG with its diagonal blocks."""
    path = tmp_path / "bar.yaml"
    path.write_text(textwrap.dedent(CASE).format(material=LPS) + f"  integrator: {integrator}\n")
    assert load_case(str(path))["time"]["integrator"] == integrator


def test_lps_refuses_what_factorises_the_tangent(tmp_path):
    path = tmp_path / "bar.yaml"
    path.write_text(textwrap.dedent(CASE).format(material=LPS) + "  integrator: implicit\n")
    assert load_case(str(path))["time"]["integrator"] == "implicit"  # auto: matrix-free CG
    path.write_text(textwrap.dedent(CASE).format(material=LPS) + "  integrator: implicit\n"
                    "implicit:\n  linear_solver: direct\n")
    with pytest.raises(CaseError, match="bar.yaml:11: implicit.linear_solver: direct factorises"):
        load_case(str(path))
    path.write_text(textwrap.dedent(CASE).format(material=LPS) + "  integrator: quasi_static\n"
                    "quasi_static:\n  linear_solver: direct\n")
    with pytest.raises(CaseError, match="bar.yaml:11: quasi_static.linear_solver: direct factorises"):
        load_case(str(path))
    path.write_text(textwrap.dedent(CASE).format(material=LPS) + "  integrator: quasi_static\n"
                    "quasi_static:\n  preconditioner: amg\n")
    with pytest.raises(CaseError, match="bar.yaml:11: quasi_static.preconditioner: amg is set up on the assembled"):
        load_case(str(path))


def test_an_lps_case_is_accepted_with_its_defaults(tmp_path):
    path = tmp_path / "bar.yaml"
    path.write_text(textwrap.dedent(CASE).format(
        material="{model: lps, density: 7850, youngs_modulus: 2.1e11, poisson_ratio: 0.29}"))
    case = load_case(str(path))
    assert case["materials"]["bar"]["model"] == "lps"
    assert case["materials"]["bar"]["influence"] is None  # the solver's default: one


@pytest.mark.parametrize("influence", ["one", "gaussian"])
def test_the_checked_stable_step_is_the_solvers_for_lps(influence, tmp_path, pdsolve, monkeypatch):
    """The membrane (2D, plane stress) in LPS: the step preprocess checks (pdsolve --physics on its
    cloud and case) equals pdsolve --stable-dt on the files it writes."""
    monkeypatch.setenv("PDSOLVE", pdsolve)
    case_dir = os.path.join(ROOT, "cases", "membrane")
    with open(os.path.join(case_dir, "membrane.yaml"), encoding="utf-8") as stream:
        text = stream.read()
    assert text.count("    youngs_modulus: 3.0e9") == 1
    yaml = tmp_path / "membrane.yaml"
    yaml.write_text(text.replace("    youngs_modulus: 3.0e9", "    model: lps\n    poisson_ratio: 0.35\n"
                                 f"    influence: {influence}\n    youngs_modulus: 3.0e9"))
    mesh = str(tmp_path / "mesh.msh")
    assert driver.main(["mesh", str(yaml), os.path.join(case_dir, "membrane.geo"), mesh]) == 0
    assert driver.main(["preprocess", str(yaml), mesh, str(tmp_path)]) == 0
    with open(tmp_path / "case.json", encoding="utf-8") as stream:
        resolved = json.load(stream)
    assert resolved["blocks"][0]["model"] == "lps" and resolved["blocks"][0]["influence"] == influence
    ours = physics_of_cloud(resolved, read_node_file(str(tmp_path / "nodes.vtu")), solver=pdsolve)["stable"]
    out = subprocess.run([pdsolve, str(tmp_path / "case.json"), "--stable-dt"], check=True,
                         capture_output=True, text=True).stdout
    assert ours == json.loads(out)["stable"]
