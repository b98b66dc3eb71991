"""End to end: a coarse cases/plate_3d (the shipped 3D case: twice the node spacing, an eighth of
the nodes) goes through every stage as the Makefile calls them: a 3D lattice fills the plate with
its through hole, the plate is pulled to fracture, the cracks start at the hole's edge
perpendicular to the load and run to the long edges, and post-processing draws the crack path,
the tip speeds and the 3D damage view."""
import csv
import os
import shutil

import numpy as np
import pytest
import yaml

from e2e_support import ROOT, new_case_folder, run_stages  # noqa: E402

DX = 1.0e-3   # m: the shipped case has 0.5 mm


@pytest.fixture(scope="module")
def plate_run(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "plate_3d", "plate_3d")
    shutil.copy(os.path.join(ROOT, "cases", "plate_3d", "plate_3d.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "plate_3d", "plate_3d.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    case["discretization"]["dx"] = DX
    case["node_sets"] = {"left": {"layer": 3.0e-3}, "right": {"layer": 3.0e-3}}  # as deep as the horizon
    yaml_path = case_dir / "plate_3d.yaml"
    yaml_path.write_text(yaml.safe_dump(case, allow_unicode=True))
    out = work / "out" / "plate_3d"
    run_stages(yaml_path, case_dir / "plate_3d.geo", out)
    return out, case


def history(out):
    with open(out / "history.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def test_the_plate_is_a_3d_lattice_with_a_through_hole(plate_run):
    import meshio
    out, case = plate_run
    p = case["geometry"]["parameters"]
    x = meshio.read(out / "nodes.vtu").points
    assert np.allclose(np.ptp(x, axis=0), [p["L"] - DX, p["W"] - DX, p["T"] - DX])   # cell-centred lattice
    layers = np.unique(np.round(x[:, 2] / DX - 0.5))
    assert len(layers) == round(p["T"] / DX)
    r = np.hypot(x[:, 0] - p["L"] / 2, x[:, 1] - p["W"] / 2)
    assert r.min() >= p["a"] - 1e-12                    # no node in the hole
    per_layer = [np.count_nonzero(np.isclose(x[:, 2], DX * (k + 0.5))) for k in layers]
    # every layer the same: the full 40 × 20 grid less the cells whose centres are in the hole
    in_hole = sum(np.hypot(DX * (i + 0.5) - p["L"] / 2, DX * (j + 0.5) - p["W"] / 2) < p["a"]
                  for i in range(round(p["L"] / DX)) for j in range(round(p["W"] / DX)))
    assert per_layer == [round(p["L"] / DX) * round(p["W"] / DX) - in_hole] * len(layers)


def test_pulled_to_fracture_from_the_hole_edge_across_the_plate(plate_run):
    out, case = plate_run
    p = case["geometry"]["parameters"]
    h = history(out)
    force = h["reaction_right_fx"]
    peak = int(np.argmax(force))
    assert h["broken_bonds"][peak] > 0                      # the peak comes with the first cracks
    assert force[-1] < 0.5 * force[peak]                    # then the plate separates
    with open(out / "crack_tips.csv", newline="") as stream:
        rows = [r for r in csv.DictReader(stream) if r["y"]]
    first = {r["tip"]: r for r in reversed(rows)}           # each tip's first row
    last = {r["tip"]: r for r in rows}
    assert sorted(last) == ["+y end", "−y end"]
    for name, sign in (("+y end", 1.0), ("−y end", -1.0)):
        # starts at the hole's edge, perpendicular to the load, and ends at the long edge
        assert abs(float(first[name]["x"]) - p["L"] / 2) <= 1.5 * DX
        assert sign * (float(first[name]["y"]) - p["W"] / 2) == pytest.approx(p["a"], abs=2 * DX)
        assert abs(float(last[name]["x"]) - p["L"] / 2) <= 2 * DX
        assert sign * (float(last[name]["y"]) - p["W"] / 2) >= p["W"] / 2 - 1.5 * DX
        speeds = [float(r["speed"]) for r in rows if r["tip"] == name and r["speed"]]
        # below the Rayleigh speed of PMMA (ν = 1/4 in 3D PMB): c_R ≈ 0.92 √(E / 2.5ρ) ≈ 950 m/s
        assert 0.0 < max(speeds) < 950.0


def test_figures_of_a_3d_fracture_run(plate_run):
    out, _ = plate_run
    for name in ("crack_path.png", "damage_3d.png", "damage_3.png", "energy.png", "reaction_force.png"):
        assert os.path.getsize(out / "figures" / name) > 15000, name
