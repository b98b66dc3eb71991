"""With `discretization.surface_correction: energy` the solver multiplies each bond's term of thesis
eq. 2.5 by its correction factor g. The step preprocess checks with is the solver's (`pdsolve
--physics` on a temporary copy of the cloud and case, pipeline/solver_physics.py): equal to
`pdsolve --stable-dt` on the written case.json, for PMB and LPS, 2D and 3D, and with a pre-crack; the
correction does move the step, and --physics reports its factors' range (not 1 with a correction, 1
without); the same for `surface_correction: volume`. (Before issue 37 the Python side had its own
copy of both corrections, held equal to the solver's here.)"""
import json
import os
import subprocess

import pytest

from pipeline import run as driver
from pipeline.solver_physics import physics_of_cloud
from preprocess.node_file import read_node_file

from common.paths import REPOSITORY as ROOT

LPS = "    model: lps\n    poisson_ratio: 0.3\n"
# (case, the text to change, its replacement): the 3D plate at 2 dx (40 × 20 × 3 nodes) and the
# branching plate (its pre-crack) at 2 dx and 2 δ (150 × 60) to stay quick.
VARIANTS = {
    "membrane-pmb": ("membrane", "", ""),
    "membrane-lps": ("membrane", "    youngs_modulus: 3.0e9", LPS + "    youngs_modulus: 3.0e9"),
    "plate_3d-pmb": ("plate_3d", "", ""),
    "plate_3d-lps": ("plate_3d", "    youngs_modulus: 3.2e9", LPS + "    youngs_modulus: 3.2e9"),
    "branching-pmb": ("branching", "", ""),
}


def steps(name, tmp_path, pdsolve, correction, monkeypatch):
    case, old, new = VARIANTS[name]
    case_dir = os.path.join(ROOT, "cases", case)
    with open(os.path.join(case_dir, case + ".yaml"), encoding="utf-8") as stream:
        text = stream.read()
    coarse = {"plate_3d": [("  dx: 5.0e-4 ", "  dx: 1.0e-3 ")],
              "branching": [("  dx: 3.3333333333333335e-4 ", "  dx: 6.666666666666667e-4 "),
                            ("  horizon: 1.0e-3 ", "  horizon: 2.0e-3 ")]}
    for a, b in coarse.get(case, []):
        assert text.count(a) == 1
        text = text.replace(a, b)
    assert (not old or text.count(old) >= 1) and text.count("\ndiscretization:\n") == 1
    text = text.replace(old, new, 1) if old else text
    text = text.replace("\ndiscretization:\n", f"\ndiscretization:\n  surface_correction: {correction}\n")
    work = tmp_path / correction
    work.mkdir()
    yaml = work / (case + ".yaml")
    yaml.write_text(text)
    mesh = str(work / "mesh.msh")
    monkeypatch.setenv("PDSOLVE", pdsolve)
    assert driver.main(["mesh", str(yaml), os.path.join(case_dir, case + ".geo"), mesh]) == 0
    assert driver.main(["preprocess", str(yaml), mesh, str(work)]) == 0
    with open(work / "case.json", encoding="utf-8") as stream:
        resolved = json.load(stream)
    assert resolved["surface_correction"] == correction
    asked = physics_of_cloud(resolved, read_node_file(str(work / "nodes.vtu")), solver=pdsolve)
    assert asked["surface_correction"]["method"] == correction
    g = asked["surface_correction"]["bond_factor"]
    assert (g == [1.0, 1.0]) == (correction == "none")
    out = subprocess.run([pdsolve, str(work / "case.json"), "--stable-dt"], check=True,
                         capture_output=True, text=True).stdout
    return asked["stable"], json.loads(out)["stable"]


@pytest.mark.parametrize("name", sorted(VARIANTS))
def test_the_checked_step_is_the_solvers_with_the_energy_correction(name, tmp_path, pdsolve, monkeypatch):
    ours, solver = steps(name, tmp_path, pdsolve, "energy", monkeypatch)
    plain, _ = steps(name, tmp_path, pdsolve, "none", monkeypatch)
    print(f"{name}: stable step {solver:.6e} s corrected, {plain:.6e} s without")
    assert ours == solver
    assert abs(solver / plain - 1.0) > 1e-3  # the factors do change the step


@pytest.mark.parametrize("name", ["membrane-pmb", "plate_3d-lps", "branching-pmb"])
def test_the_checked_step_is_the_solvers_with_the_volume_correction(name, tmp_path, pdsolve, monkeypatch):
    """`surface_correction: volume`: g = 2V0/(V_i + V_j) per bond (volume_factors)."""
    ours, solver = steps(name, tmp_path, pdsolve, "volume", monkeypatch)
    plain, _ = steps(name, tmp_path, pdsolve, "none", monkeypatch)
    print(f"{name}: stable step {solver:.6e} s with the volume correction, {plain:.6e} s without")
    assert ours == solver
    assert abs(solver / plain - 1.0) > 1e-3
