"""End to end: a shortened impact run (cases/impact, coarser and shorter) goes through every stage;
contact keeps the disk out of the plate, the Verlet list is rebuilt now and then, bonds break.

The stages are called exactly as the Makefile calls them, on a copy of cases/impact.
"""
import csv
import os
import shutil
import subprocess

import meshio
import numpy as np
import pytest
import yaml
from scipy.spatial import cKDTree

from e2e_support import PY, ROOT, SOLVER, new_case_folder  # noqa: E402
DX = 2.5e-4


def coarsen(case):
    """The short version's model (also test_mpi_contact.py's): twice the node spacing (a quarter of
    the nodes) and a gap wider than the larger horizon."""
    case["discretization"]["dx"] = DX
    case["geometry"]["parameters"].update({"gap": 1.0e-3, "lc": 0.002})
    case["node_sets"] = {"left": {"layer": 8.0e-4}, "right": {"layer": 8.0e-4}}


@pytest.fixture(scope="module")
def impact_run(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "impact", "impact")
    shutil.copy(os.path.join(ROOT, "cases", "impact", "impact.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "impact", "impact.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    # Short version: the coarser model, and the first 25 µs: the disk hits the plate at about 5 µs.
    coarsen(case)
    case["time"]["end"] = 2.5e-5
    case["output"] = {"every_time": 2.5e-6, "history_every": 5}
    case["figures"]["times"] = [0.0, 2.5e-5]
    yaml_path = case_dir / "impact.yaml"
    yaml_path.write_text(yaml.safe_dump(case))
    out = work / "out" / "impact"
    env = dict(os.environ, PYTHONPATH=ROOT)
    for args in (
        (PY, "-m", "pipeline.run", "mesh", str(yaml_path), str(case_dir / "impact.geo"), str(out / "mesh.msh")),
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


def test_the_solver_plans_contact_and_says_so(impact_run):
    log = (impact_run / "run.log").read_text()
    assert "work: contact search (cell list + Verlet list) between all nodes (self_contact)" in log
    assert "work: breakage test after every step" in log
    assert "work: no indenters" in log


def test_contact_columns_rebuilds_and_breaking(impact_run):
    history = read_history(impact_run / "history.csv")
    steps = history["step"][-1]
    rebuilds = history["contact_rebuilds"]
    assert rebuilds[0] == 1                      # the first build, at t = 0
    assert np.all(np.diff(rebuilds) >= 0)
    assert 2 < rebuilds[-1] < steps / 3          # the skin rule rebuilds now and then, not every step
    assert history["contact_energy"][0] == 0.0   # the bodies start apart
    assert history["contact_energy"].max() > 0.0
    assert history["broken_bonds"][-1] > 100     # the plate cracks under the disk
    assert (impact_run / "figures" / "energy.png").is_file()


def test_disk_never_enters_the_plate_and_slows_down(impact_run):
    nodes = meshio.read(impact_run / "nodes.vtu")
    projectile = nodes.point_data["set_projectile"].astype(bool)
    frames = sorted((impact_run / "frames").glob("frame_*.vtu"))
    assert len(frames) == 11
    closest = np.inf
    for path in frames:
        frame = meshio.read(path)
        y = frame.points + frame.point_data["displacement"]
        distance, _ = cKDTree(y[~projectile]).query(y[projectile])
        closest = min(closest, distance.min())
    # The contact distance is 1.35·dx; at 150 m/s a node pair is squeezed, but never through.
    assert closest > 0.4 * DX
    assert closest < 1.35 * DX  # they did touch
    v_end = meshio.read(frames[-1]).point_data["velocity"][projectile, 1].mean()
    assert -150.0 < v_end < -50.0  # slowed by the plate, not stopped
