"""End to end: a shortened membrane run goes through every stage and every promised file appears.

The stages are called exactly as the Makefile calls them (pipeline.run, pdsolve,
postprocess), on a copy of cases/membrane with a shorter end time.
"""
import csv
import os
import shutil
import subprocess

import meshio
import numpy as np
import pytest
import yaml

from e2e_support import PY, ROOT, SOLVER, new_case_folder  # noqa: E402
from postprocess.history import read_history  # noqa: E402
from postprocess.history_units import FIXED_COLUMNS  # noqa: E402


@pytest.fixture(scope="module")
def membrane_run(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "membrane", "membrane")
    shutil.copy(os.path.join(ROOT, "cases", "membrane", "membrane.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    # Short version: a coarser lattice and a fifth of the run, still several oscillation periods' worth
    # of damping (KE must fall), fast enough for `make test`.
    case["time"]["end"] = 4.0e-3
    case["output"] = {"every_time": 4.0e-4}
    case["figures"]["times"] = [0.0, 2.0e-3, 4.0e-3]
    yaml_path = case_dir / "membrane.yaml"
    yaml_path.write_text(yaml.safe_dump(case))
    out = work / "out" / "membrane"
    env = dict(os.environ, PYTHONPATH=ROOT)
    for args in (
        (PY, "-m", "pipeline.run", "mesh", str(yaml_path), str(case_dir / "membrane.geo"), str(out / "mesh.msh")),
        (PY, "-m", "pipeline.run", "preprocess", str(yaml_path), str(out / "mesh.msh"), str(out)),
        (SOLVER, str(out / "case.json"), "--quiet"),
        (PY, "-m", "postprocess", str(out)),
    ):
        result = subprocess.run(list(args), cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
        assert result.returncode == 0, f"{' '.join(args)} failed:\n{result.stdout}\n{result.stderr}"
    return out


def read_history(path):
    with open(path, newline="") as stream:
        rows = list(csv.DictReader(stream))
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def test_every_promised_file_exists(membrane_run):
    out = membrane_run
    for name in ("mesh.msh", "nodes.vtu", "case.json", "frames.pvd", "history.csv", "history.json", "run.log",
                 "figures/energy.png", "figures/timestep.png", "gmsh/results.msh"):
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name
    frames = sorted((out / "frames").glob("frame_*.vtu"))
    assert len(frames) == 11  # t = 0 and every 0.4 ms up to 4 ms
    # the membrane cannot break (no fracture_energy): displacement maps, no all-zero damage maps
    assert len(list((out / "figures").glob("displacement_*.png"))) == 3
    assert not list((out / "figures").glob("damage_*.png"))


def test_frames_are_readable_and_clamped_edge_stays_put(membrane_run):
    out = membrane_run
    nodes = meshio.read(out / "nodes.vtu")
    last = meshio.read(sorted((out / "frames").glob("frame_*.vtu"))[-1])
    assert last.points.shape == nodes.points.shape
    u = last.point_data["displacement"]
    clamped = nodes.point_data["set_clamped"].astype(bool)
    assert clamped.sum() > 0
    assert np.all(u[clamped] == 0.0)
    assert np.abs(u[~clamped, 2]).max() > 0.0  # the membrane moved out of plane
    assert np.all(np.isfinite(u))


def test_energy_is_dissipated_and_balanced(membrane_run):
    history = read_history(membrane_run / "history.csv")
    ke, strain = history["kinetic_energy"], history["strain_energy"]
    mechanical = ke + strain
    assert ke[0] > 0.0 and strain[0] == 0.0
    # Damping (α = 300/s) only removes energy and the clamped edge does no work, so the
    # mechanical energy falls: by 4 ms it is below exp(-α·t) ≈ 0.30 of the start.
    assert history["external_work"][-1] == 0.0
    assert mechanical[-1] < 0.35 * mechanical[0]
    # Energy balance (docs/theory.md C4): KE + U + damping work is conserved to the
    # integration error of velocity Verlet.
    balance = mechanical + history["damping_work"] - history["external_work"]
    assert np.abs(balance - balance[0]).max() < 1e-3 * balance[0]
    assert np.all(np.diff(history["time"]) > 0)
    assert np.all(history["broken_bonds"] == 0)  # no fracture_energy: unbreakable


def test_a_single_body_runs_no_contact_search(membrane_run):
    # One block, no self_contact, no indenters: the solver plans no contact work; its history.csv
    # still has every fixed column, the absent terms as 0 (formats.md §4, issue 16).
    log = (membrane_run / "run.log").read_text()
    assert "work: no contact search (one body and no self_contact)" in log
    assert "work: no indenters" in log
    assert "work: no breakage test (every block unbreakable)" in log
    header = (membrane_run / "history.csv").read_text().splitlines()[0].split(",")
    assert header == list(FIXED_COLUMNS)  # no indenters, no output.reactions: nothing more
    history = read_history(str(membrane_run / "history.csv"))
    for absent in ("contact_energy", "indenter_energy", "broken_bond_energy", "contact_rebuilds", "mode"):
        assert np.all(history[absent] == 0), absent
