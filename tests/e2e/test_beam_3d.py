"""cases/beam_3d (the 3D notched beam in three-point bending, quasi-static): its coarse config is
meshed and preprocessed as the Makefile does (16 000 nodes, the support and load lines across the
thickness, the notch), and a tiny variant (dx = 4 mm) is solved for a few load steps with CG
preconditioned by algebraic multigrid: the work plan names the preconditioner, every step is in
equilibrium and the load grows linearly with the load-point displacement before any bond breaks."""
import csv
import os
import shutil

import numpy as np
import pytest
import yaml

from e2e_support import ROOT, SOLVER, _run, new_case_folder, prepare_stages  # noqa: E402


def load_case(name):
    with open(os.path.join(ROOT, "cases", "beam_3d", name + ".yaml"), encoding="utf-8") as stream:
        return yaml.safe_load(stream)


@pytest.fixture(scope="module")
def coarse(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "beam_3d", "beam_3d")
    shutil.copy(os.path.join(ROOT, "cases", "beam_3d", "beam_3d.geo"), case_dir)
    shutil.copy(os.path.join(ROOT, "cases", "beam_3d", "coarse.yaml"), case_dir)
    out = work / "out" / "beam_3d-coarse"
    prepare_stages(case_dir / "coarse.yaml", case_dir / "beam_3d.geo", out)
    return out, load_case("coarse")


def test_the_shipped_case_is_the_coarse_one_at_half_the_spacing_over_1e5_nodes():
    full, coarse = load_case("beam_3d"), load_case("coarse")
    assert coarse["discretization"]["dx"] == 2 * full["discretization"]["dx"]
    p, dx = full["geometry"]["parameters"], full["discretization"]["dx"]
    assert round(p["L"] / dx) * round(p["W"] / dx) * round(p["B"] / dx) == 128000  # the lattice fills the box
    for key in ("geometry", "materials", "boundary_conditions", "cracks", "quasi_static", "time"):
        assert full[key] == coarse[key], key
    assert full["time"]["integrator"] == "quasi_static" and full["quasi_static"]["linear_solver"] == "cg"


def test_the_coarse_lattice_has_its_supports_load_line_and_notch(coarse):
    import meshio
    out, case = coarse
    p, dx = case["geometry"]["parameters"], case["discretization"]["dx"]
    nodes = meshio.read(out / "nodes.vtu")
    x = nodes.points
    assert len(x) == 16000
    assert np.allclose(x.min(axis=0), [dx / 2] * 3) and np.allclose(x.max(axis=0), [p["L"] - dx / 2, p["W"] - dx / 2, p["B"] - dx / 2])
    for name, centre, y in (("support_left", (p["L"] - p["S"]) / 2, dx / 2), ("support_right", (p["L"] + p["S"]) / 2, dx / 2),
                            ("load", p["L"] / 2, p["W"] - dx / 2)):
        member = nodes.point_data["set_" + name].astype(bool)
        # two columns of nodes (the 4 mm patch) in the first row under the face, across the whole thickness
        assert member.sum() == 2 * round(p["B"] / dx), name
        assert np.allclose(x[member, 1], y) and np.allclose(np.unique(x[member, 0]), [centre - dx / 2, centre + dx / 2])
    notch = json_case(out)["cracks"]
    assert len(notch) == 1


def json_case(out):
    import json
    with open(out / "case.json", encoding="utf-8") as stream:
        return json.load(stream)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "beam_3d_tiny", "beam_3d")
    shutil.copy(os.path.join(ROOT, "cases", "beam_3d", "beam_3d.geo"), case_dir)
    case = load_case("beam_3d")
    case["discretization"]["dx"] = 4.0e-3  # 50 × 10 × 4 = 2 000 nodes
    case["geometry"]["parameters"]["p"] = 4.0e-3
    case["quasi_static"]["preconditioner"] = "amg"  # auto would take block_jacobi at this size
    case["time"]["end"] = 0.1                        # 5 load steps to 0.08 mm, below the first break
    case["output"]["every_time"] = 0.02
    case["figures"]["times"] = [0.0, 0.1]
    yaml_path = case_dir / "tiny.yaml"
    yaml_path.write_text(yaml.safe_dump(case, allow_unicode=True))
    out = work / "out" / "beam_3d-tiny"
    prepare_stages(yaml_path, case_dir / "beam_3d.geo", out)
    _run((SOLVER, str(out / "case.json"), "--quiet"))
    return out


def test_a_tiny_beam_is_solved_with_amg_and_is_linear_before_the_first_break(tiny):
    log = (tiny / "run.log").read_text()
    assert "algebraic multigrid" in log and "preconditioner amg: as the case file asks" in log
    with open(tiny / "history.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    t = np.array([float(r["time"]) for r in rows])
    force = np.array([-float(r["reaction_load_fy"]) for r in rows])
    assert t[-1] == pytest.approx(0.1, rel=1e-12)
    broken = [int(r["broken_bonds"]) for r in rows]
    assert broken[0] > 0 and broken == [broken[0]] * len(rows)  # the notch's bonds, and no more
    assert force[-1] > 0
    stiffness = force[1:] / (8.0e-4 * t[1:])  # N/m: the load point at −0.8 mm × t
    assert np.allclose(stiffness, stiffness[-1], rtol=1e-3)  # linear: PMB below the first break
