"""Lengths, the body the .geo makes and the cost of meshing it, checked before gmsh meshes
(pipeline/body.py; issue 17, items 10 and 11). Each mistake is an error at the .yaml line."""
import glob
import os
import shutil
import subprocess
import sys
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def copy_case(tmp_path, case: str, old: str, new: str):
    """cases/<case>/ copied to tmp_path/<case>/ with one text of its .yaml replaced."""
    folder = tmp_path / case
    folder.mkdir()
    shutil.copy(os.path.join(ROOT, "cases", case, f"{case}.geo"), folder)
    text = open(os.path.join(ROOT, "cases", case, f"{case}.yaml"), encoding="utf-8").read()
    assert old in text
    (folder / f"{case}.yaml").write_text(text.replace(old, new))
    return folder / f"{case}.yaml"


def run(*args, env=None, timeout=120):
    return subprocess.run([sys.executable, "-m", "pipeline.run", *map(str, args)], cwd=ROOT, capture_output=True,
                          text=True, timeout=timeout, env=env)


@pytest.mark.parametrize("case, old, new, message", [
    ("plate_with_hole", "a: 0.005", "a: -0.005",
     "plate_with_hole.yaml:10: geometry.parameters.a: -0.005 m, but plate_with_hole.geo says 'a' is a length "
     "(Parameters/hole radius [m]): give a length > 0"),
    ("impact", "lc: 0.001", "lc: 0",
     "impact.yaml:10: geometry.parameters.lc: 0 m, but impact.geo says 'lc' is a length (Parameters/mesh size [m])"),
])
def test_a_length_of_the_geo_must_be_positive(tmp_path, case, old, new, message):
    """gmsh meshed `a: -0.005` as the same hole as 0.005, without a word."""
    result = run("check", copy_case(tmp_path, case, old, new))
    assert result.returncode == 2, result.stdout + result.stderr
    assert message in result.stderr


@pytest.mark.parametrize("case, old, new, hole, body", [
    # a hole radius larger than the plate: gmsh meshed the disk around the plate instead
    ("plate_with_hole", "a: 0.005", "a: 0.06", "hole x -0.01…0.11, y -0.035…0.085", "body x 0…0.1, y 0…0.05"),
    # a hole crossing the plate's edge: gmsh failed only while meshing ("Unable to recover the edge")
    ("plate_with_hole", "a: 0.005", "a: 0.03", "hole x 0.02…0.08, y -0.005…0.055", "body x 0…0.1, y 0…0.05"),
    # the membrane's centre disk wider than the membrane
    ("membrane", "r: 0.006", "r: 0.03", "hole x -0.005…0.055, y -0.005…0.055", "body x 0…0.05, y 0…0.05"),
])
def test_a_hole_outside_the_body_is_named_at_the_parameters_line(tmp_path, case, old, new, hole, body):
    path = copy_case(tmp_path, case, old, new)
    result = run("check", path)
    assert result.returncode == 2, result.stdout + result.stderr
    assert f"{case}.yaml:10: in " in result.stderr
    assert "surface 1 has a hole" in result.stderr and "a hole larger than the body or crossing its edge" in result.stderr
    assert f"({hole}; {body}); make the hole smaller or the body larger" in result.stderr
    # the mesh stage refuses it too, before gmsh meshes: no mesh file
    result = run("mesh", path, path.parent / f"{case}.geo", tmp_path / "mesh.msh")
    assert result.returncode == 2 and "a hole larger than the body" in result.stderr
    assert not (tmp_path / "mesh.msh").exists()


def test_a_material_that_is_no_group_of_the_geo(tmp_path):
    path = copy_case(tmp_path, "plate_with_hole", "  plate:", "  plates:")
    result = run("check", path)
    assert result.returncode == 2
    assert "materials.plates: " in result.stderr and "has no physical group 'plates'; its 2D groups are: plate" \
        in result.stderr


def test_a_mesh_size_that_would_mesh_for_ever_stops_at_once(tmp_path):
    """`lc: 2e-6` meshed for ever; now the estimate is the error, in seconds, with no mesh."""
    path = copy_case(tmp_path, "plate_with_hole", "lc: 0.002", "lc: 2e-6")
    env = dict(os.environ)
    env.pop("FORCE", None)
    start = time.monotonic()
    result = run("mesh", path, path.parent / "plate_with_hole.geo", tmp_path / "mesh.msh", env=env, timeout=60)
    assert time.monotonic() - start < 30
    assert result.returncode == 2, result.stdout + result.stderr
    # bounding box 0.1 m × 0.05 m at h = 2e-6 m: 0.005 / (√3/2 · 4e-12) = 1.44e9 nodes
    assert "plate_with_hole.yaml:10: estimate before meshing: gmsh: about 1.44e+09 mesh nodes at mesh size 2e-06 m" \
        in result.stderr
    assert "meshing would take about" in result.stderr and "(more than 1 h)" in result.stderr
    assert "or run it anyway with FORCE=1 (make FORCE=1 case=...)" in result.stderr
    assert not (tmp_path / "mesh.msh").exists()


def test_the_estimate_of_a_shipped_case_passes_and_force_lets_a_large_one_through(tmp_path):
    from pipeline.body import check_mesh_cost, probe_geometry
    from pipeline.case import CaseError, load_case

    geo = os.path.join(ROOT, "cases", "plate_with_hole", "plate_with_hole.geo")
    case = load_case(os.path.join(ROOT, "cases", "plate_with_hole", "plate_with_hole.yaml"))
    plan = check_mesh_cost(case, geo, probe_geometry(case, geo), str(tmp_path), force=False)
    # 0.005 m² / (√3/2 · 0.002²) = 1443 mesh nodes; lattice (0.1/2.5e-4 + 1)(0.05/2.5e-4 + 1) = 80601
    assert plan.startswith("estimate before meshing: gmsh: about 1.44e+03 mesh nodes at mesh size 0.002 m")
    assert "lattice: at most 8.06e+04 nodes" in plan
    case["geometry"]["parameters"]["lc"] = 2e-6
    with pytest.raises(CaseError):
        check_mesh_cost(case, geo, probe_geometry(case, geo), str(tmp_path), force=False)
    assert "1.44e+09 mesh nodes" in check_mesh_cost(case, geo, probe_geometry(case, geo), str(tmp_path), force=True)


@pytest.mark.parametrize("yaml", sorted(glob.glob(os.path.join(ROOT, "cases", "*", "*.yaml"))))
def test_every_shipped_case_passes(yaml):
    result = run("check", yaml)
    assert result.returncode == 0, result.stderr
    assert "is sound" in result.stdout


L_SHAPED_GEO = """\
// An L-shaped plate (the corner x > 0.05, y > 0.05 cut away) with a round hole at (c, 0.075).
DefineConstant[ r = {0.01, Name "Parameters/hole radius [m]"}, c = {0.02, Name "Parameters/hole centre x [m]"} ];
Point(1) = {0, 0, 0, 0.005}; Point(2) = {0.1, 0, 0, 0.005}; Point(3) = {0.1, 0.05, 0, 0.005};
Point(4) = {0.05, 0.05, 0, 0.005}; Point(5) = {0.05, 0.1, 0, 0.005}; Point(6) = {0, 0.1, 0, 0.005};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6}; Line(6) = {6, 1};
Point(7) = {c, 0.075, 0, 0.005}; Point(8) = {c + r, 0.075, 0, 0.005}; Point(9) = {c - r, 0.075, 0, 0.005};
Circle(7) = {8, 7, 9}; Circle(8) = {9, 7, 8};
Curve Loop(1) = {1, 2, 3, 4, 5, 6}; Curve Loop(2) = {7, 8};
Plane Surface(1) = {1, 2};
Physical Surface("plate") = {1};
"""


@pytest.mark.parametrize("c, outside", [(0.02, None), (0.08, "66 of 66"), (0.05, "of 66")])
def test_a_hole_in_the_missing_corner_of_an_l_shaped_plate(tmp_path, c, outside):
    """Inside the outer loop's box but not inside the loop: gmsh meshed it without a word; the
    hole's outline, sampled, is tested against the outer loop as a polygon."""
    from minimal_case import MINIMAL

    folder = tmp_path / "ell"
    folder.mkdir()
    (folder / "ell.geo").write_text(L_SHAPED_GEO)
    (folder / "ell.yaml").write_text(MINIMAL.replace("discretization:", f"geometry:\n  parameters: {{r: 0.01, c: {c}}}\n"
                                                     "discretization:"))
    result = run("check", folder / "ell.yaml")
    if outside is None:
        assert result.returncode == 0, result.stderr
        return
    assert result.returncode == 2, result.stdout
    assert "ell.yaml:4: in " in result.stderr and "surface 1 has a hole (its boundary [-8, -7]) partly or wholly " \
        "outside its outer boundary [1, 2, 3, 4, 5, 6] (" in result.stderr
    assert f"{outside} points of the hole's outline lie outside the body): move the hole into the body" in result.stderr


def test_a_mesh_size_field_finer_than_the_mesh_size_stops_before_meshing(tmp_path):
    """A `Background Field` bypassed the estimate (722 nodes estimated, then gmsh meshed until its
    time limit): the probe meshes the boundary with everything the .geo sets and extrapolates."""
    folder = tmp_path / "field"
    folder.mkdir()
    shutil.copy(os.path.join(ROOT, "cases", "plate_with_hole", "plate_with_hole.yaml"), folder / "field.yaml")
    geo = folder / "field.geo"
    geo.write_text(open(os.path.join(ROOT, "cases", "plate_with_hole", "plate_with_hole.geo")).read()
                   + 'Field[1] = MathEval; Field[1].F = "2e-6"; Background Field = 1;\n')
    env = dict(os.environ, PD_GMSH_TIMEOUT="20")   # today's code meshes until this limit
    env.pop("FORCE", None)
    start = time.monotonic()
    result = run("mesh", folder / "field.yaml", geo, tmp_path / "out" / "mesh.msh", env=env, timeout=120)
    assert time.monotonic() - start < 15
    assert result.returncode == 2, result.stdout + result.stderr
    # 165,708 curve elements of 2e-6 m; the bounding box 0.1 m × 0.05 m / (√3/2 · 4e-12) = 1.44e9 nodes
    assert (f"field.yaml:10: {geo}: gmsh meshed the body's curves with 165709 nodes, 2e-06 m apart on average "
            "(the estimate from the case's mesh size 0.002 m was about 1.44e+03 nodes); at that size the 2D mesh "
            "would have about 1.44e+09 nodes: meshing would take about") in result.stderr, result.stderr
    assert "a mesh size field (Field, Background Field) or the size of a point makes the mesh finer" in result.stderr
    assert result.stderr.endswith("coarsen it, or run it anyway with FORCE=1 (make FORCE=1 case=...)\n")
    # no mesh, nothing half-written: at most the folder's lock, which make leaves in out/<case>/ too
    assert not (tmp_path / "out").exists() or os.listdir(tmp_path / "out") in ([], [".lock"])
