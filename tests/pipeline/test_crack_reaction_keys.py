"""Case-file keys `cracks` (pre-cracks) and `output.reactions`: resolution and bad values."""
import textwrap

import pytest

from pipeline.case import CaseError, load_case
from pipeline.resolve import resolve

MINIMAL = """\
dimension: 2
thickness: 0.001
discretization:
  dx: 0.001
materials:
  plate:
    density: 2000
    youngs_modulus: 1.0e9
    fracture_energy: 10.0
time:
  end: 1.0e-3
"""


def load(tmp_path, extra=""):
    path = tmp_path / "plate.yaml"
    path.write_text(MINIMAL + textwrap.dedent(extra))
    return load_case(str(path))


def error_of(tmp_path, extra):
    with pytest.raises(CaseError) as info:
        load(tmp_path, extra)
    return str(info.value)


def test_cracks_and_reactions_resolve(tmp_path):
    case = load(tmp_path, """\
        cracks:
          - {from: [0.0, 0.02], to: [0.05, 0.02]}
        output:
          reactions: [right]
        """)
    resolved = resolve(case, node_sets=["plate", "right"], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert resolved["cracks"] == [{"from": [0.0, 0.02, 0.0], "to": [0.05, 0.02, 0.0]}]
    assert resolved["output"]["reactions"] == ["right"]


def test_defaults_are_empty(tmp_path):
    resolved = resolve(load(tmp_path), node_sets=["plate"], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert resolved["cracks"] == [] and resolved["output"]["reactions"] == []


def test_bad_cracks_are_reported_with_their_line(tmp_path):
    text = error_of(tmp_path, """\
        cracks:
          - {from: [0.0, 0.02, 0.0, 1.0], to: [0.05, 0.02]}
          - {from: [0.01, 0.01], to: [0.01, 0.01]}
        """)
    assert "plate.yaml:13: cracks[0].from: expected 2 or 3 components, got 4" in text
    assert "plate.yaml:14: cracks[1]: from and to are the same point" in text
    assert "plate.yaml:13: cracks[0].to: missing required key" in error_of(tmp_path, """\
        cracks:
          - {from: [0.01, 0.01]}
        """)


def test_reaction_of_an_unknown_set_names_the_sets(tmp_path):
    case = load(tmp_path, """\
        output:
          reactions: [rigth]
        """)
    with pytest.raises(CaseError) as info:
        resolve(case, node_sets=["plate", "right"], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert "node set 'rigth' is not a physical group of the mesh (did you mean 'right'?)" in str(info.value)
