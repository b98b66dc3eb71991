"""The case-file keys of LAMMPS-compatible PMB (docs/lammps.md): c and s0 given directly, α,
breaking_order and discretization.origin; errors name the file, the line and the key."""
import textwrap

import numpy as np
import pytest

from pipeline.case import CaseError, load_case
from pipeline.resolve import resolve
from pipeline.solver_physics import physics_of_cloud
from preprocess.cloud import NodeCloud

LAMMPS_LIKE = """\
dimension: 3
discretization:
  dx: 0.001
  horizon: 0.0030002
  origin: [0, 0, 0]
  partial_volume: lammps
materials:
  brick:
    density: 2440
    micromodulus: 3.4e21
    critical_stretch: 0.001
    critical_stretch_alpha: 0.25
breaking_order: lammps
time:
  end: 1.0e-5
"""


def solver_micromodulus(resolved):
    """c of the case's block as pdsolve computes it (pdsolve --physics), on a 4³ lattice."""
    side, dx = 4, resolved["grid_spacing"]
    points = np.array([[i, j, k] for k in range(side) for j in range(side) for i in range(side)], float) * dx
    cloud = NodeCloud(points=points, volume=np.full(len(points), dx ** 3), block=np.ones(len(points), np.int32),
                      sets={}, grid_spacing=dx, dimension=3)
    return physics_of_cloud(resolved, cloud)["blocks"][0]["micromodulus"]


def write(tmp_path, text):
    path = tmp_path / "brick.yaml"
    path.write_text(textwrap.dedent(text))
    return str(path)


def error_of(tmp_path, text):
    with pytest.raises(CaseError) as info:
        load_case(write(tmp_path, text))
    return str(info.value)


PAIRS = "give youngs_modulus (and fracture_energy) or micromodulus (and critical_stretch), not a mix"


def test_a_lammps_like_case_reaches_case_json(tmp_path):
    case = load_case(write(tmp_path, LAMMPS_LIKE))
    assert case["discretization"]["origin"] == [0, 0, 0]
    resolved = resolve(case, node_sets=[], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert resolved["breaking_order"] == "lammps"
    assert resolved["blocks"][0] == {"id": 1, "name": "brick", "model": "pmb", "density": 2440,
                                     "micromodulus": 3.4e21, "critical_stretch": 0.001,
                                     "critical_stretch_alpha": 0.25}
    # eq. 2.5's c for the stable step is the given one
    assert solver_micromodulus(resolved) == 3.4e21


def test_the_defaults_keep_the_thesis(tmp_path):
    text = LAMMPS_LIKE.replace("breaking_order: lammps\n", "").replace("    critical_stretch_alpha: 0.25\n", "")
    case = load_case(write(tmp_path, text))
    assert case["breaking_order"] == "thesis"
    assert case["materials"]["brick"]["critical_stretch_alpha"] is None  # 0: s0 fixed
    assert "critical_stretch_alpha" not in resolve(case, node_sets=[], grid_spacing=0.001,
                                                   nodes_file="nodes.vtu")["blocks"][0]
    e = 7.2e10
    by_e = load_case(write(tmp_path, text.replace("micromodulus: 3.4e21", f"youngs_modulus: {e}")
                           .replace("    critical_stretch: 0.001\n", "")))
    # c from E by docs/theory.md T2 in 3D, 12E/(πδ⁴)
    resolved = resolve(by_e, node_sets=[], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert solver_micromodulus(resolved) == pytest.approx(12.0 * e / (np.pi * 0.0030002 ** 4), rel=1e-14)


def test_both_pairs_given_is_an_error_at_its_line(tmp_path):
    message = error_of(tmp_path, LAMMPS_LIKE.replace("    micromodulus: 3.4e21\n",
                                                     "    micromodulus: 3.4e21\n    youngs_modulus: 7.2e10\n"))
    assert f"brick.yaml:10: materials.brick.micromodulus: is given beside youngs_modulus: {PAIRS}" in message


def test_a_mix_of_the_pairs_is_an_error(tmp_path):
    message = error_of(tmp_path, LAMMPS_LIKE.replace("critical_stretch: 0.001", "fracture_energy: 4"))
    assert f"brick.yaml:11: materials.brick.fracture_energy: is given with micromodulus: {PAIRS}" in message
    message = error_of(tmp_path, LAMMPS_LIKE.replace("micromodulus: 3.4e21", "youngs_modulus: 7.2e10"))
    assert f"brick.yaml:11: materials.brick.critical_stretch: is given with youngs_modulus: {PAIRS}" in message


def test_no_stiffness_is_an_error(tmp_path):
    message = error_of(tmp_path, LAMMPS_LIKE.replace("    micromodulus: 3.4e21\n", ""))
    assert f"brick.yaml:8: materials.brick: needs a stiffness: {PAIRS}" in message


def test_alpha_must_be_at_least_zero_and_needs_a_breakable_material(tmp_path):
    message = error_of(tmp_path, LAMMPS_LIKE.replace("critical_stretch_alpha: 0.25", "critical_stretch_alpha: -0.1"))
    assert "brick.yaml:12: materials.brick.critical_stretch_alpha: must be at least 0, got -0.1" in message
    message = error_of(tmp_path, LAMMPS_LIKE.replace("    critical_stretch: 0.001\n", ""))
    assert ("materials.brick.critical_stretch_alpha: needs a breakable material: give fracture_energy or "
            "critical_stretch") in message
    load_case(write(tmp_path, LAMMPS_LIKE.replace("critical_stretch_alpha: 0.25", "critical_stretch_alpha: 0")))


def test_breaking_order_is_a_choice(tmp_path):
    message = error_of(tmp_path, LAMMPS_LIKE.replace("breaking_order: lammps", "breaking_order: lamps"))
    assert "brick.yaml:13: breaking_order: 'lamps' is not one of 'thesis', 'lammps'" in message


def test_origin_needs_a_lattice_and_the_dimension_s_coordinates(tmp_path):
    message = error_of(tmp_path, LAMMPS_LIKE.replace("origin: [0, 0, 0]", "origin: [0, 0]"))
    assert "brick.yaml:5: discretization.origin: needs 3 coordinates (dimension 3), got 2" in message
    message = error_of(tmp_path, LAMMPS_LIKE.replace("  dx: 0.001\n", "  method: mesh-nodes\n"))
    assert ("brick.yaml:5: discretization.origin: origin places a lattice; the mesh-nodes method has none: "
            "remove origin or use method: lattice") in message
    assert np.isfinite(load_case(write(tmp_path, LAMMPS_LIKE))["discretization"]["dx"])


def test_lammps_keys_belong_to_pmb(tmp_path):
    lps = (LAMMPS_LIKE.replace("    micromodulus: 3.4e21\n", "    model: lps\n    youngs_modulus: 7.2e10\n"
                               "    poisson_ratio: 0.3\n")
           .replace("    critical_stretch: 0.001\n", "").replace("    critical_stretch_alpha: 0.25\n", ""))
    message = error_of(tmp_path, lps)
    assert ("brick.yaml:13: breaking_order: lammps is LAMMPS peri/pmb's order, for model pmb; remove it or "
            "use model: pmb") in message
    message = error_of(tmp_path, lps.replace("breaking_order: lammps\n", "").replace(
        "    poisson_ratio: 0.3\n", "    poisson_ratio: 0.3\n    critical_stretch: 0.001\n"))
    assert "materials.brick.critical_stretch:" in message and "belongs to model pmb" in message
