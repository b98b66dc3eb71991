"""discretization.origin: the lattice through a given point (nodes at origin + k·dx, as LAMMPS's
`lattice` puts atoms at k·a), instead of the cell centres of the mesh's bounding box."""
import math

import numpy as np
import pytest

from preprocess_testdata import PLATE
from preprocess import PreprocessError, build_node_cloud, read_mesh

THICK = 1e-3
DX = 5e-4


def cloud(meshes, origin):
    # A lattice off the cell centres sits up to dx from an edge: the edges' node sets take a layer of dx.
    edges = {name: DX for name, group in read_mesh(meshes["plate"]).groups.items() if group.dim == 1}
    return build_node_cloud(meshes["plate"], dimension=2, thickness=THICK, method="lattice", dx=DX,
                            block_names=["plate"], set_layers=edges if origin is not None else {},
                            lattice_origin=origin)


@pytest.fixture(scope="module")
def centred(meshes):
    return cloud(meshes, None)


def keyed(points):
    return set(map(tuple, np.round(points[:, :2] / DX * 4).astype(np.int64)))  # quarter-dx keys


def test_origin_on_a_cell_centre_is_the_default_lattice(meshes, centred):
    # The plate's box starts at (0, 0): the default nodes are at (i + ½)·dx.
    shifted = cloud(meshes, [0.5 * DX, 0.5 * DX])
    assert len(shifted.volume) == len(centred.volume)
    assert keyed(shifted.points) == keyed(centred.points)


def test_nodes_are_exactly_origin_plus_k_dx(meshes):
    origin = [0.0, 0.0]  # LAMMPS: atoms at k·a
    c = cloud(meshes, origin)
    k = np.rint(c.points[:, :2] / DX)
    assert np.array_equal(c.points[:, :2], k * DX)  # bitwise k·dx
    odd = [0.123 * DX, -7.377 * DX]  # any point of the plane
    c = cloud(meshes, odd)
    k = np.rint((c.points[:, :2] - odd) / DX)
    assert np.array_equal(c.points[:, :2], odd + k * DX)
    # still the plate: the volume is its area to within the lattice's resolution
    area = PLATE["L"] * PLATE["W"] - math.pi * PLATE["r"] ** 2
    assert c.volume.sum() == pytest.approx(area * THICK, rel=5e-3)
    assert np.all(c.points[:, 0] > 0) and np.all(c.points[:, 0] < PLATE["L"])


def test_a_shifted_origin_moves_every_node(meshes, centred):
    c = cloud(meshes, [0.0, 0.0])
    assert keyed(c.points).isdisjoint(keyed(centred.points))  # k·dx vs (i + ½)·dx


def test_origin_of_the_wrong_length_is_an_error(meshes):
    with pytest.raises(PreprocessError, match="the lattice origin needs 2 coordinates, got 3"):
        cloud(meshes, [0.0, 0.0, 0.0])
