"""figures.probe (postprocess only, pipeline/schema.py): a point or a node set, checked before any work."""
import textwrap

import pytest

from pipeline.case import CaseError, load_case
from pipeline.resolve import check_set_names, resolve

CASE = """\
dimension: {dimension}
thickness: 0.001
discretization:
  dx: 0.001
materials:
  plate:
    density: 2000
    youngs_modulus: 1.0e9
time:
  end: 1.0e-3
figures:
  probe: {probe}
"""


def load(tmp_path, probe, dimension=2):
    path = tmp_path / "plate.yaml"
    path.write_text(textwrap.dedent(CASE.format(probe=probe, dimension=dimension)))
    return load_case(str(path))


def test_a_point_or_a_set_name_reaches_case_json(tmp_path):
    case = load(tmp_path, "[0.01, 0.02]")
    assert case["figures"]["probe"] == [0.01, 0.02]
    resolved = resolve(case, node_sets=["plate", "edge"], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert resolved["figures"]["probe"] == [0.01, 0.02]
    case = load(tmp_path, "edge")
    resolved = resolve(case, node_sets=["plate", "edge"], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert resolved["figures"]["probe"] == "edge"
    assert load(tmp_path, "null")["figures"]["probe"] is None


@pytest.mark.parametrize("probe, message", [
    ("[0.01]", "plate.yaml:12: figures.probe: expected a point [x, y] or [x, y, z] [m] or a node-set name"),
    ("[0.01, a, 0]", "plate.yaml:12: figures.probe[1]: expected a number [m], got 'a'"),
    ("{x: 1}", "figures.probe: expected a point"),
    ("'2edge'", "figures.probe: expected a point"),
])
def test_a_bad_probe_names_the_line(tmp_path, probe, message):
    with pytest.raises(CaseError, match=message.replace("[", r"\[").replace("]", r"\]")):
        load(tmp_path, probe)


def test_a_3d_point_has_three_coordinates(tmp_path):
    with pytest.raises(CaseError, match=r"figures.probe: a point of a 3D case has three coordinates"):
        load(tmp_path, "[0.01, 0.02]", dimension=3)


def test_an_unknown_probe_set_is_named_with_the_mesh_groups(tmp_path):
    case = load(tmp_path, "egde")
    with pytest.raises(CaseError, match=r"plate.yaml:12: node set 'egde' is not a physical group of the mesh "
                                        r"\(did you mean 'edge'\?\)"):
        check_set_names(case, ["plate", "edge"])


def test_figures_dpi_defaults_to_print_and_reaches_case_json(tmp_path):
    case = load(tmp_path, "null")
    assert case["figures"]["dpi"] == 300
    resolved = resolve(case, node_sets=["plate"], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert resolved["figures"]["dpi"] == 300
    path = tmp_path / "plate.yaml"
    path.write_text(path.read_text() + "  dpi: 150\n")
    assert load_case(str(path))["figures"]["dpi"] == 150


@pytest.mark.parametrize("dpi", ["20", "1300", "150.5"])
def test_figures_dpi_outside_its_range_names_the_line(tmp_path, dpi):
    path = tmp_path / "plate.yaml"
    path.write_text(textwrap.dedent(CASE.format(probe="null", dimension=2)) + f"  dpi: {dpi}\n")
    with pytest.raises(CaseError, match=r"plate\.yaml:\d+: figures\.dpi"):
        load_case(str(path))
