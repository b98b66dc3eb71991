"""`make check` (pipeline.run check CASE [MESH]): with the mesh at hand, material and node-set names
are checked against its physical groups before any work (issue 16: a misspelt set was caught only
at preprocess). The mesh: tests/preprocess/data/plate_hole.geo (surfaces plate, main, grip; curves
left, right, hole)."""
import os
import textwrap

import pytest

from pipeline import run
from preprocess.gmsh_mesh import mesh_geo

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

CASE = """\
dimension: 2
thickness: 0.001
discretization:
  dx: 0.001
materials:
  {material}:
    density: 2000
    youngs_modulus: 1.0e9
  grip:
    density: 7800
    youngs_modulus: 2.0e11
boundary_conditions:
  - set: {bc_set}
    displacement: {{x: 0}}
time:
  end: 1.0e-3
figures:
  probe: {probe}
"""


@pytest.fixture(scope="module")
def mesh(tmp_path_factory):
    path = tmp_path_factory.mktemp("mesh") / "plate.msh"
    mesh_geo(os.path.join(ROOT, "tests", "preprocess", "data", "plate_hole.geo"), str(path), 2, {})
    return str(path)


def check(tmp_path, mesh, capsys, material="main", bc_set="left", probe="hole"):
    path = tmp_path / "plate.yaml"
    path.write_text(textwrap.dedent(CASE.format(material=material, bc_set=bc_set, probe=probe)))
    status = run.main(["check", str(path)] + ([mesh] if mesh else []))
    out = capsys.readouterr()
    return status, out.out + out.err


def test_names_that_match_the_mesh_pass(tmp_path, mesh, capsys):
    status, text = check(tmp_path, mesh, capsys)
    assert status == 0 and f"materials and node sets match the physical groups of {mesh}" in text


def test_misspelt_names_are_errors_at_their_lines(tmp_path, mesh, capsys):
    status, text = check(tmp_path, mesh, capsys, material="mian", bc_set="lefft", probe="hoel")
    assert status == 2
    assert "plate.yaml:6: materials.mian: block 'mian' is not a physical group of the mesh" in text
    assert "(did you mean 'main'?)" in text
    assert "plate.yaml:13: node set 'lefft' is not a physical group of the mesh (did you mean 'left'?)" in text
    assert "plate.yaml:18: node set 'hoel' is not a physical group of the mesh (did you mean 'hole'?)" in text


def test_a_curve_is_no_material(tmp_path, mesh, capsys):
    status, text = check(tmp_path, mesh, capsys, material="left")
    assert status == 2 and "block 'left' is a 1D physical group, not a 2D one" in text


def test_without_a_mesh_only_the_case_file_is_checked(tmp_path, capsys):
    status, text = check(tmp_path, None, capsys, bc_set="lefft")
    assert status == 0 and "match the physical groups" not in text


def test_make_check_passes_the_mesh_when_it_exists():
    with open(os.path.join(ROOT, "Makefile"), encoding="utf-8") as stream:
        makefile = stream.read()
    assert "$(PY) -m pipeline.run check '$(YAML)' $(if $(wildcard $(MESH)),'$(MESH)')" in makefile
