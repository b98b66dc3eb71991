"""Checks of the discretized case (pipeline/stability.py): isolated nodes, the eq. 2.5 time step, unit
mistakes; every message names the file, the line and the key; and the driver writes nothing on error."""
import itertools
import os
import subprocess
import textwrap

import numpy as np
import pytest

from pipeline.case import CaseError, load_case
from pipeline.resolve import resolve
from pipeline.stability import check_discretized_case
from preprocess.cloud import NodeCloud
from minimal_case import PMMA_PLATE, lattice_cloud
from common.paths import PYTHON

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

CASE = PMMA_PLATE


def checked(tmp_path, text, cloud=None):
    path = tmp_path / "plate.yaml"
    path.write_text(textwrap.dedent(text))
    case = load_case(str(path))
    cloud = cloud if cloud is not None else lattice_cloud()
    resolved = resolve(case, node_sets=[], grid_spacing=cloud.grid_spacing, nodes_file="nodes.vtu")
    return check_discretized_case(case, resolved, cloud)


def error_of(tmp_path, text, cloud=None):
    with pytest.raises(CaseError) as info:
        checked(tmp_path, text, cloud)
    return str(info.value)


@pytest.mark.parametrize("density, modulus", [(1190, 3.2e9), (7850, 2.1e11), (2440, 7.2e10), (1100, 5e6)])
def test_realistic_materials_pass_silently(tmp_path, density, modulus):
    text = CASE.replace("density: 1190", f"density: {density}").replace("youngs_modulus: 3.2e9",
                                                                        f"youngs_modulus: {modulus}")
    assert checked(tmp_path, text) == []


def test_g_per_cm3_and_mpa_are_warned_about_with_file_line_key(tmp_path):
    text = CASE.replace("density: 1190", "density: 1.19").replace("youngs_modulus: 3.2e9", "youngs_modulus: 3200")
    warnings = checked(tmp_path, text)
    path = str(tmp_path / "plate.yaml")
    assert any(w.startswith(f"{path}:7: materials.plate.density: 1.19 kg/m³") and "g/cm³" in w for w in warnings)
    assert any(w.startswith(f"{path}:8: materials.plate.youngs_modulus: 3200 Pa") and "MPa" in w for w in warnings)


def test_absurd_number_of_steps_is_refused_naming_end_and_material(tmp_path):
    # E in Pa mistyped as e21: the stable step shrinks by 10⁶, the run would need ~10¹² steps.
    message = error_of(tmp_path, CASE.replace("youngs_modulus: 3.2e9", "youngs_modulus: 3.2e21")
                       .replace("end: 1.0e-4", "end: 10.0"))
    path = str(tmp_path / "plate.yaml")
    assert message.startswith(f"{path}:10: time.end: the run would need ")
    assert f"material 'plate' ({path}:6: materials.plate)" in message and "E = 3.2e+21 Pa" in message
    steps = float(message.split("would need ")[1].split(" steps")[0])
    assert 1e12 < steps < 1e14


def test_run_shorter_than_one_stable_step_is_refused(tmp_path):
    # E in GPa (3.2 for 3.2e9) and ρ in g/cm³ make the stable step ~10⁶ times too long.
    message = error_of(tmp_path, CASE.replace("youngs_modulus: 3.2e9", "youngs_modulus: 3.2e-3")
                       .replace("end: 1.0e-4", "end: 1.0e-3"))
    assert f"{tmp_path / 'plate.yaml'}:10: time.end: time.end = 0.001 s is shorter than one stable" in message


def test_fixed_step_too_small_is_refused_and_too_large_warned(tmp_path):
    message = error_of(tmp_path, CASE + "  dt: 1.0e-15\n")
    assert message.startswith(f"{tmp_path / 'plate.yaml'}:11: time.dt: the run would need 1e+11 steps")
    warnings = checked(tmp_path, CASE + "  dt: 1.0e-6\n")
    assert len(warnings) == 1 and warnings[0].startswith(f"{tmp_path / 'plate.yaml'}:11: time.dt: 1e-06 s "
                                                         "exceeds the stable step")


def test_isolated_node_is_warned_about_with_its_position(tmp_path):
    cloud = lattice_cloud(extra=[(0.05, 0.05, 0.0)])   # far from the lattice
    warnings = checked(tmp_path, CASE, cloud)
    assert len(warnings) == 1
    assert warnings[0].startswith(f"{tmp_path / 'plate.yaml'}:3: discretization.horizon_factor: 1 node(s) "
                                  "have no bond")
    assert "node 120 at (0.05, 0.05, 0)" in warnings[0]


def test_horizon_below_spacing_and_no_bonds_are_errors(tmp_path):
    # mesh-nodes: the spacing is known only after discretization, so validate.py cannot catch it.
    text = CASE.replace("  dx: 0.001\n", "  method: mesh-nodes\n  horizon: 0.0005\n")
    assert "discretization.horizon: the horizon 0.0005 m is smaller than the node spacing 0.001 m" in \
        error_of(tmp_path, text)
    sparse = lattice_cloud(dx=0.004)
    sparse.grid_spacing = 0.0001                         # a spacing that lies about the cloud
    text = CASE.replace("  dx: 0.001\n", "  method: mesh-nodes\n  horizon: 0.0003\n")
    assert "no node has a bond" in error_of(tmp_path, text, sparse)


# The unit square as two triangles (UNV), physical groups 'plate' (surface) and 'left' (nodes).
SQUARE_UNV = """\
    -1
  2411
         1         1         1        11
   0.0000000000000000D+00   0.0000000000000000D+00   0.0000000000000000D+00
         2         1         1        11
   1.0000000000000000D-02   0.0000000000000000D+00   0.0000000000000000D+00
         3         1         1        11
   1.0000000000000000D-02   1.0000000000000000D-02   0.0000000000000000D+00
         4         1         1        11
   0.0000000000000000D+00   1.0000000000000000D-02   0.0000000000000000D+00
    -1
    -1
  2412
         1        41         1         1         7         3
         1         2         3
         2        41         1         1         7         3
         1         3         4
    -1
    -1
  2477
         1         0         0         0         0         0         0         2
plate
         8         1         0         0         8         2         0         0
         2         0         0         0         0         0         0         2
left
         7         1         0         0         7         4         0         0
    -1
"""


def test_driver_refuses_before_writing_anything(tmp_path):
    mesh = tmp_path / "square.unv"
    mesh.write_text(SQUARE_UNV)
    case = tmp_path / "square.yaml"
    case.write_text(CASE.replace("youngs_modulus: 3.2e9", "youngs_modulus: 3.2e21").replace("end: 1.0e-4", "end: 10.0")
                    + "boundary_conditions:\n  - set: left\n    displacement: {x: 0.0}\n")
    out = tmp_path / "out"
    result = subprocess.run([PYTHON, "-m", "pipeline.run", "preprocess", str(case), str(mesh), str(out)],
                            cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith(f"error: {case}:10: time.end: the run would need")
    assert not out.exists() or [p.name for p in out.iterdir()] in ([], [".lock"])   # at most its lock
    case.write_text(CASE.replace("density: 1190", "density: 1.19"))
    result = subprocess.run([PYTHON, "-m", "pipeline.run", "preprocess", str(case), str(mesh), str(out)],
                            cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert f"warning: {case}:7: materials.plate.density: 1.19 kg/m³" in result.stderr
    assert sorted(p.name for p in out.iterdir()) == [".lock", "case.json", "nodes.vtu"]


def test_every_lattice_node_has_bonds_in_the_membrane_case():
    """No false alarm on the shipped case: its lattice and material pass silently (a smoke check of
    the rule 'warn only when something is really odd')."""
    case = load_case(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"))
    dx = case["discretization"]["dx"]
    n = 20
    pts = np.array([(i * dx, j * dx, 0.0) for i, j in itertools.product(range(n), range(n))])
    cloud = NodeCloud(points=pts, volume=np.full(n * n, dx * dx * case["thickness"]),
                      block=np.ones(n * n, np.int32), sets={}, grid_spacing=dx, dimension=2)
    resolved = resolve(case, node_sets=["clamped", "centre", "membrane"], grid_spacing=dx, nodes_file="n.vtu")
    assert check_discretized_case(case, resolved, cloud) == []


def test_a_material_that_is_no_physical_group_is_reported_at_its_case_line(tmp_path):
    """Two materials need two 2D physical groups; the square mesh has only 'plate', so 'grip' is
    reported at its own line of the case file, naming the mesh, before anything is written."""
    mesh = tmp_path / "square.unv"
    mesh.write_text(SQUARE_UNV)
    case = tmp_path / "square.yaml"
    case.write_text(CASE.replace("time:\n", "  gripp:\n    density: 7800\n    youngs_modulus: 2.0e11\ntime:\n"))
    out = tmp_path / "out"
    result = subprocess.run([PYTHON, "-m", "pipeline.run", "preprocess", str(case), str(mesh), str(out)],
                            cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith(f"error: {case}:9: materials.gripp: block 'gripp' is not a physical group of "
                                    f"the mesh in {mesh}; a material names the physical group holding its nodes, "
                                    f"and the mesh's 2D groups are: plate"), result.stderr
    assert not out.exists() or [p.name for p in out.iterdir()] in ([], [".lock"])   # at most its lock
