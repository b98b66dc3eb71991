"""End to end: the traction specimen loaded quasi-statically (cases/traction/quasi_static.yaml, on
a coarser lattice and only up to 0.2 mm, before any bond breaks) goes through every stage: the
quasi_static section passes from the YAML through case.json to the solver, every load step is in
equilibrium, the grips' work is stored as strain energy, and the force grows linearly with the
displacement."""
import csv
import os
import shutil

import numpy as np
import pytest
import yaml

from e2e_support import ROOT, new_case_folder, run_stages  # noqa: E402


@pytest.fixture(scope="module")
def quasi_static_run(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "quasi_static", "traction")
    shutil.copy(os.path.join(ROOT, "cases", "traction", "traction.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "traction", "quasi_static.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    case["discretization"]["dx"] = 5.0e-4  # 7 600 nodes instead of 30 000
    case["time"]["end"] = 4.0e-4           # grips at 0.2 mm each: below the first bond failure (0.25 mm at this dx)
    case["figures"]["times"] = [0.0, 4.0e-4]
    yaml_path = case_dir / "quasi_static.yaml"
    yaml_path.write_text(yaml.safe_dump(case))
    out = work / "out" / "traction-quasi_static"
    run_stages(yaml_path, case_dir / "traction.geo", out)
    return out


def history(out):
    with open(out / "history.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def test_the_quasi_static_settings_reach_the_solver(quasi_static_run):
    log = (quasi_static_run / "run.log").read_text()
    assert "integrator quasi_static" in log
    assert "dt_max 2e-05 s" in log  # quasi_static.dt_max of the YAML
    h = history(quasi_static_run)
    assert h["time"][-1] == pytest.approx(4.0e-4, rel=1e-12)
    assert np.all(h["broken_bonds"] == 0)
    assert np.all(h["iterations"][1:] >= 1) and np.all(h["iterations"][1:] <= 30)


def test_the_grips_work_is_stored_as_strain_energy(quasi_static_run):
    h = history(quasi_static_run)
    work, strain = h["external_work"][-1], h["strain_energy"][-1]
    assert strain > 0.0
    # Equilibrium at every load step and the trapezoidal work of the linearly growing reaction:
    # equal to well below 0.1 % (the explicit run's damping and kinetic energy are absent).
    assert abs(work - strain) < 1e-3 * strain


def test_the_force_grows_linearly_with_the_displacement(quasi_static_run):
    h = history(quasi_static_run)
    displacement = 7.0e-4 * h["time"] / 1.4e-3  # the right grip's table
    force = h["reaction_right_fx"]
    stiffness = force[1:] / displacement[1:]
    # PMB below failure is linear up to its geometric nonlinearity, O(strain) ~ 0.5 % here.
    assert stiffness.max() - stiffness.min() < 0.02 * stiffness.mean()
    assert stiffness.mean() > 0.0
