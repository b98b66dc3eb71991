"""A node-set layer on one face of a notch stops at the notch (issue 16: a 3 mm layer on one face
reached across a 1.5 mm notch to the nodes under the other face), and keeps its documented round
cap of radius `layer` ahead of the notch tip (preprocess/discretize.py)."""
import numpy as np
import pytest

from preprocess import build_node_cloud
from preprocess.gmsh_mesh import mesh_geo

# A 20 mm × 10 mm plate with a 1.5 mm wide, 10 mm deep notch from its left edge; the notch's
# upper face y = 5.75 mm, x ∈ [0, 10] mm, is the physical curve "upper_face".
GEO = """\
lc = 0.001;
Point(1) = {0, 0, 0, lc}; Point(2) = {0.02, 0, 0, lc}; Point(3) = {0.02, 0.01, 0, lc};
Point(4) = {0, 0.01, 0, lc}; Point(5) = {0, 0.00575, 0, lc}; Point(6) = {0.01, 0.00575, 0, lc};
Point(7) = {0.01, 0.00425, 0, lc}; Point(8) = {0, 0.00425, 0, lc};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8};
Plane Surface(1) = {1};
Physical Surface("plate") = {1};
Physical Curve("upper_face") = {5};
"""
DX = 2.5e-4
FACE_Y, BOTTOM_Y, TIP_X = 0.00575, 0.00425, 0.01
LAYER = 3.0e-3


@pytest.fixture(scope="module")
def cloud(tmp_path_factory):
    out = tmp_path_factory.mktemp("notch")
    (out / "notch.geo").write_text(GEO)
    mesh_geo(str(out / "notch.geo"), str(out / "notch.msh"), 2, {})
    return build_node_cloud(str(out / "notch.msh"), dimension=2, thickness=1e-3, method="lattice", dx=DX,
                            block_names=["plate"], set_layers={"upper_face": LAYER})


def distance_to_face(points):
    x = np.clip(points[:, 0], 0.0, TIP_X)
    return np.hypot(points[:, 0] - x, points[:, 1] - FACE_Y)


def test_the_layer_does_not_cross_the_notch(cloud):
    x, y = cloud.points[:, 0], cloud.points[:, 1]
    in_set = cloud.sets["upper_face"]
    below = (y < BOTTOM_Y) & (x < TIP_X - 1e-9)
    assert np.any(below & (distance_to_face(cloud.points) <= LAYER))  # nodes the old rule took
    assert not np.any(in_set & below)


def test_the_layer_is_full_on_its_own_side_with_a_round_cap_ahead_of_the_tip(cloud):
    x, y = cloud.points[:, 0], cloud.points[:, 1]
    in_set = cloud.sets["upper_face"]
    near = distance_to_face(cloud.points) <= LAYER - 1e-9
    above = y > FACE_Y
    assert np.array_equal(in_set[above], near[above])
    ahead = x > TIP_X  # in front of the tip the body is whole: the cap of radius LAYER is kept
    assert np.array_equal(in_set[ahead], near[ahead])
    assert np.any(in_set & ahead & (y < BOTTOM_Y))  # the cap reaches round the tip, through the body
