"""Case-file keys of contact, indenters and partial volumes: defaults, resolution and bad values."""
import textwrap

import pytest

from pipeline.case import CaseError, load_case
from pipeline.resolve import resolve

from minimal_case import MINIMAL


def load(tmp_path, extra=""):
    path = tmp_path / "plate.yaml"
    text = MINIMAL + textwrap.dedent(extra)
    if "discretization:" in extra:  # replace the minimal case's own section
        text = text.replace("discretization:\n  dx: 0.001\n", "", 1)
    path.write_text(text)
    return load_case(str(path))


def error_of(tmp_path, extra):
    with pytest.raises(CaseError) as info:
        load(tmp_path, extra)
    return str(info.value)


def test_defaults_and_resolution(tmp_path):
    case = load(tmp_path, """\
        indenters:
          - {name: punch, shape: plane, centre: [0, 0.01], normal: [0, -2], velocity: [0, -1], stiffness: 1.0e15}
          - {name: ball, shape: cylinder, radius: 0.002, centre: [0.01, 0.02], stiffness: 1.0e14}
        """)
    assert case["contact"] == {"enabled": "auto", "self_contact": False, "skin": None, "stiffness_factor": 15.0}
    assert case["discretization"]["partial_volume"] == "none"
    resolved = resolve(case, node_sets=[], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert resolved["contact"]["skin"] == pytest.approx(0.0005)  # dx/2
    assert resolved["partial_volume"] == "none"
    punch, ball = resolved["indenters"]
    assert punch["normal"] == [0.0, -1.0, 0.0] and punch["centre"] == [0.0, 0.01, 0.0]
    assert punch["velocity"] == [0.0, -1.0, 0.0] and "radius" not in punch
    assert ball["axis"] == [0.0, 0.0, 1.0] and ball["velocity"] == [0.0, 0.0, 0.0]


@pytest.mark.parametrize("extra, message", [
    ("contact: {enabled: sometimes}\n", "contact.enabled: 'sometimes' is not one of 'auto', 'on', 'off'"),
    ("contact: {self_contact: 1}\n", "contact.self_contact: expected true or false, got 1"),
    ("contact: {skin: -0.001}\n", "contact.skin: must be greater than 0 [m], got -0.001"),
    ("contact: {stiffnes_factor: 10}\n", "unknown key (did you mean 'stiffness_factor'?)"),
    ("discretization: {dx: 0.001, partial_volume: exact}\n",
     "discretization.partial_volume: 'exact' is not one of 'none', 'lammps', 'hhb'"),
    ("indenters:\n  - {name: p, shape: cone, centre: [0, 0], stiffness: 1}\n",
     "indenters[0].shape: 'cone' is not one of 'sphere', 'cylinder', 'plane'"),
    ("indenters:\n  - {name: p, shape: sphere, centre: [0, 0], stiffness: 1}\n",
     "indenters[0].radius: a sphere indenter needs radius [m]"),
    ("indenters:\n  - {name: p, shape: plane, centre: [0, 0], normal: [0, 0], stiffness: 1}\n",
     "indenters[0].normal: must be a non-zero direction"),
    ("indenters:\n  - {name: p, shape: plane, centre: [0, 0, 0, 0], normal: [0, 1], stiffness: 1}\n",
     "indenters[0].centre: expected 2 or 3 components, got 4"),
    ("indenters:\n  - {name: p, shape: plane, centre: [0, 0], normal: [0, 1], stiffness: 0}\n",
     "indenters[0].stiffness: must be greater than 0 [N/m⁵], got 0"),
    ("indenters:\n  - {name: 1p, shape: plane, centre: [0, 0], normal: [0, 1], stiffness: 1}\n",
     "indenters[0].name: letters, digits and '_'"),
    ("indenters:\n  - {name: a, shape: plane, centre: [0, 0], normal: [0, 1], stiffness: 1}\n"
     "  - {name: a, shape: plane, centre: [0, 0], normal: [0, 1], stiffness: 1}\n",
     "indenters[1].name: 'a' is used twice"),
])
def test_bad_values_name_file_line_and_key(tmp_path, extra, message):
    text = error_of(tmp_path, extra)
    assert message in text
    assert "plate.yaml:" in text
