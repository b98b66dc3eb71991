"""Discretization: node volumes add up to the exact geometry, node sets match the physical groups."""
import math

import numpy as np
import pytest

from preprocess_testdata import BOX, PLATE
from preprocess import PreprocessError, build_node_cloud, read_mesh

THICK = 1e-3
DX2 = 5e-4     # 2D lattice spacing: L/dx = 200, W/dx = 100, g/dx = 20 exactly
DX3 = 5e-4     # 3D lattice spacing: 80 × 40 × 20 cells


def plate_area():
    return PLATE["L"] * PLATE["W"] - math.pi * PLATE["r"] ** 2


def hole_centre():
    return np.array([(PLATE["L"] - PLATE["g"]) / 2, PLATE["W"] / 2])


@pytest.fixture(scope="module")
def lattice(meshes):
    return build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="lattice", dx=DX2,
                            block_names=["plate"], set_layers={})


@pytest.fixture(scope="module")
def mesh_nodes(meshes):
    return build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="mesh-nodes", dx=None,
                            block_names=["plate"], set_layers={})


def test_lattice_volume_is_plate_area_times_thickness(lattice):
    assert lattice.volume.sum() == pytest.approx(plate_area() * THICK, rel=5e-3)
    assert np.all(lattice.volume == DX2 ** 2 * THICK)
    assert lattice.grid_spacing == DX2 and lattice.dimension == 2
    assert np.all(lattice.points[:, 2] == 0.0)


def test_lattice_nodes_are_cell_centres_inside_the_plate(lattice):
    i = lattice.points[:, :2] / DX2 - 0.5
    assert np.allclose(i, np.round(i), atol=1e-6)
    rho = np.linalg.norm(lattice.points[:, :2] - hole_centre(), axis=1)
    assert rho.min() >= PLATE["r"] - 1e-5        # no node inside the hole (polygon sagitta ≈ 3e-6 m)
    # every cell centre of the plate farther than dx from the hole is there: full rows of 200
    far = rho > PLATE["r"] + DX2
    expected = sum(1 for ix in range(200) for iy in range(100)
                   if np.hypot((ix + .5) * DX2 - hole_centre()[0], (iy + .5) * DX2 - hole_centre()[1])
                   > PLATE["r"] + DX2)
    assert int(far.sum()) == expected


def test_mesh_nodes_volume_is_plate_area_times_thickness(mesh_nodes, meshes):
    mesh = read_mesh(meshes["plate"])
    assert len(mesh_nodes.volume) == len(np.unique(np.concatenate([c.ravel() for t, c in mesh.cells.items()
                                                                    if t == "triangle"])))
    assert mesh_nodes.volume.sum() == pytest.approx(plate_area() * THICK, rel=5e-3)
    assert np.all(mesh_nodes.volume > 0)
    # grid spacing: median nearest-neighbour distance, between the hole's and the far mesh size
    assert PLATE["lc_hole"] * 0.5 < mesh_nodes.grid_spacing < PLATE["lc"] * 1.2


def test_lattice_edge_sets_are_the_outer_columns(lattice):
    x = lattice.points[:, 0]
    left, right = lattice.sets["left"], lattice.sets["right"]
    assert np.array_equal(left, np.isclose(x, 0.5 * DX2, rtol=0, atol=1e-9))
    assert np.array_equal(right, np.isclose(x, PLATE["L"] - 0.5 * DX2, rtol=0, atol=1e-9))
    assert left.sum() == 100 and right.sum() == 100


def test_lattice_subregion_set_and_blocks(meshes, lattice):
    grip = lattice.sets["grip"]
    assert grip.sum() == 20 * 100                   # x ∈ [0.09, 0.1]: 20 columns of 100 nodes
    assert np.array_equal(grip, lattice.points[:, 0] > PLATE["L"] - PLATE["g"])
    assert lattice.sets["plate"].all()
    assert np.array_equal(lattice.sets["main"], ~grip)
    assert np.all(lattice.block == 1)
    two = build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="lattice", dx=DX2,
                           block_names=["main", "grip"], set_layers={})
    assert np.array_equal(two.block, np.where(grip, 2, 1))


def test_lattice_hole_set_is_the_first_ring(lattice):
    rho = np.linalg.norm(lattice.points[:, :2] - hole_centre(), axis=1)
    hole = lattice.sets["hole"]
    sag = 1e-5   # polygon vs circle, generous
    assert hole.sum() > 0
    assert np.all(rho[hole] <= PLATE["r"] + 0.5 * DX2 + sag)
    assert np.all(hole[rho <= PLATE["r"] + 0.5 * DX2 - sag])


def test_layer_widens_a_curve_set(meshes):
    layer = 1.5e-3
    cloud = build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="lattice", dx=DX2,
                             block_names=["plate"], set_layers={"hole": layer, "left": layer})
    rho = np.linalg.norm(cloud.points[:, :2] - hole_centre(), axis=1)
    hole = cloud.sets["hole"]
    assert np.all(rho[hole] <= PLATE["r"] + layer + 1e-5)
    assert np.all(hole[rho <= PLATE["r"] + layer - 1e-5])
    assert cloud.sets["left"].sum() == 3 * 100       # columns at 0.25, 0.75, 1.25 mm
    assert np.array_equal(cloud.sets["left"], cloud.points[:, 0] < layer)


def test_point_group_takes_the_nearest_lattice_node(lattice):
    origin = lattice.sets["origin"]
    assert origin.sum() == 1
    assert np.allclose(lattice.points[origin][0], [0.5 * DX2, 0.5 * DX2, 0])


def test_mesh_node_sets_are_the_group_nodes(mesh_nodes, meshes):
    x = mesh_nodes.points[:, 0]
    assert np.array_equal(mesh_nodes.sets["left"], np.abs(x) < 1e-12)
    assert np.array_equal(mesh_nodes.sets["right"], np.abs(x - PLATE["L"]) < 1e-12)
    rho = np.linalg.norm(mesh_nodes.points[:, :2] - hole_centre(), axis=1)
    assert np.array_equal(mesh_nodes.sets["hole"], np.abs(rho - PLATE["r"]) < 1e-9)
    assert np.array_equal(mesh_nodes.sets["grip"], x >= PLATE["L"] - PLATE["g"] - 1e-12)
    assert mesh_nodes.sets["origin"].sum() == 1
    two = build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="mesh-nodes", dx=None,
                           block_names=["main", "grip"], set_layers={})
    # nodes on the interface x = L - g belong to both groups and take the first block, 'main'
    assert np.array_equal(two.block == 2, x > PLATE["L"] - PLATE["g"] + 1e-12)


def test_box_with_hole_lattice_and_mesh_nodes(meshes):
    L, W, H, r = BOX["L"], BOX["W"], BOX["H"], BOX["r"]
    exact = L * W * H - math.pi * r ** 2 * H
    lat = build_node_cloud(meshes["box"], dimension=3, thickness=None, method="lattice", dx=DX3,
                           block_names=["body"], set_layers={})
    assert lat.volume.sum() == pytest.approx(exact, rel=5e-3)
    assert np.all(lat.volume == DX3 ** 3)
    z = lat.points[:, 2]
    assert np.array_equal(lat.sets["bottom"], np.isclose(z, 0.5 * DX3, rtol=0, atol=1e-9))
    # a box edge: the one column of nodes nearest to it (layer √2/2 dx by default)
    edge = lat.sets["edge"]
    assert edge.sum() == 20
    assert np.allclose(lat.points[edge][:, :2], 0.5 * DX3)
    rho = np.linalg.norm(lat.points[:, :2] - [L / 2, W / 2], axis=1)
    assert np.all(rho[lat.sets["hole"]] <= r + 0.5 * DX3 + 2e-5)
    assert np.all(lat.sets["hole"][rho <= r + 0.5 * DX3 - 2e-5])
    mn = build_node_cloud(meshes["box"], dimension=3, thickness=None, method="mesh-nodes", dx=None,
                          block_names=["body"], set_layers={})
    assert mn.volume.sum() == pytest.approx(exact, rel=5e-3)
    assert np.array_equal(mn.sets["bottom"], np.abs(mn.points[:, 2]) < 1e-12)


# ---- errors -------------------------------------------------------------------------------------

def test_unknown_block_lists_the_groups(meshes):
    with pytest.raises(PreprocessError) as err:
        build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="lattice", dx=DX2,
                         block_names=["steel", "grip"], set_layers={})
    msg = str(err.value)
    assert msg.startswith(meshes["plate"]) and "'steel'" in msg and "plate, main, grip" in msg


def test_node_in_no_block(meshes, lattice):
    outside = int((~lattice.sets["grip"]).sum())
    with pytest.raises(PreprocessError, match=rf"{outside} node\(s\) lie in no block, e.g. at \("):
        build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="lattice", dx=DX2,
                         block_names=["grip"], set_layers={})
    with pytest.raises(PreprocessError, match=r"node\(s\) lie in no block"):
        build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="mesh-nodes", dx=None,
                         block_names=["grip"], set_layers={})
    with pytest.raises(PreprocessError, match="block 'left' is a 1D physical group, not a 2D one"):
        build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="lattice", dx=DX2,
                         block_names=["grip", "left"], set_layers={})


def test_blocks_must_not_overlap(meshes):
    with pytest.raises(PreprocessError, match="blocks 'plate' and 'grip' share"):
        build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="lattice", dx=DX2,
                         block_names=["plate", "grip"], set_layers={})


def test_wrong_dimension_and_missing_inputs(meshes):
    with pytest.raises(PreprocessError, match="has no 3D elements"):
        build_node_cloud(meshes["plate"], dimension=3, thickness=None, method="lattice", dx=DX2,
                         block_names=["plate"], set_layers={})
    with pytest.raises(PreprocessError, match="needs a thickness"):
        build_node_cloud(meshes["plate"], dimension=2, thickness=None, method="lattice", dx=DX2,
                         block_names=["plate"], set_layers={})
    with pytest.raises(PreprocessError, match="needs a spacing dx"):
        build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="lattice", dx=None,
                         block_names=["plate"], set_layers={})
    with pytest.raises(PreprocessError, match="unknown discretization method 'grid'"):
        build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="grid", dx=DX2,
                         block_names=["plate"], set_layers={})
    with pytest.raises(PreprocessError, match="layer given for 'lefft'"):
        build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="lattice", dx=DX2,
                         block_names=["plate"], set_layers={"lefft": 1e-3})
    with pytest.raises(PreprocessError, match="unknown mesh format '.stl'"):
        build_node_cloud("x.stl", dimension=2, thickness=THICK, method="lattice", dx=DX2,
                         block_names=["plate"], set_layers={})
