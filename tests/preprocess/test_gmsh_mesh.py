"""Meshing with the gmsh command line: parameters reach gmsh, and gmsh's own errors reach the user."""
import numpy as np
import pytest

from preprocess import PreprocessError, read_mesh
from preprocess.gmsh_mesh import mesh_geo

SQUARE = """DefineConstant[ a = {1.0, Name "a"} ];
Point(1) = {0, 0, 0, 0.5}; Point(2) = {a, 0, 0, 0.5}; Point(3) = {a, a, 0, 0.5}; Point(4) = {0, a, 0, 0.5};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Physical Surface("square") = {1};
"""


def test_parameters_are_passed(tmp_path):
    geo = tmp_path / "square.geo"
    geo.write_text(SQUARE)
    out = tmp_path / "out" / "square.msh"
    mesh_geo(str(geo), str(out), 2, {"a": 2.5})
    mesh = read_mesh(str(out))
    assert np.allclose(mesh.points.max(axis=0), [2.5, 2.5, 0])
    assert out.read_text().startswith("$MeshFormat\n4.")
    assert sorted(p.name for p in out.parent.iterdir()) == ["square.msh"]


def test_rejected_geo_shows_gmsh_message(tmp_path):
    geo = tmp_path / "bad.geo"
    geo.write_text(SQUARE + "Foo bar;\n")
    out = tmp_path / "bad.msh"
    with pytest.raises(PreprocessError) as err:
        mesh_geo(str(geo), str(out), 2, {})
    msg = str(err.value)
    assert msg.startswith(f"{geo}: gmsh failed")
    assert "Unknown command 'Foo'" in msg and "line 6" in msg     # gmsh's own words
    assert not out.exists() and [p.name for p in tmp_path.iterdir()] == ["bad.geo"]


def test_missing_geo(tmp_path):
    with pytest.raises(PreprocessError, match="no such .geo file"):
        mesh_geo(str(tmp_path / "none.geo"), str(tmp_path / "x.msh"), 2, {})
