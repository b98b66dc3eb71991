"""Space-filling-curve numbering of the node cloud (preprocess/ordering.py)."""
import itertools

import numpy as np

from preprocess import build_node_cloud
from preprocess.cloud import NodeCloud
from preprocess.ordering import morton_keys, morton_order, reorder, space_filling_order


def cubic_lattice(side: int, dx: float) -> np.ndarray:
    ijk = np.array(list(itertools.product(range(side), repeat=3)), dtype=float)
    return ijk[:, ::-1] * dx  # x fastest, as the lattice discretization writes it


def near_fraction(points: np.ndarray, dx: float, window: int = 512, m: int = 3) -> float:
    """The fraction of the bonds of a cubic lattice with horizon m·dx whose two ends are at most
    `window` apart in index: 512 nodes of positions are 12 KB, an L1 cache, so this is the share of
    partner reads the solver's bond loop (forces/pmb.cpp) finds near the row it is on."""
    cells = np.rint(points / dx).astype(np.int64)
    side = int(cells.max()) + 1
    index = np.full((side,) * 3, -1)
    index[cells[:, 0], cells[:, 1], cells[:, 2]] = np.arange(len(points))
    near, count = 0, 0
    for o in itertools.product(range(-m, m + 1), repeat=3):
        if not 0 < np.dot(o, o) <= m * m:
            continue
        partner = cells + np.array(o)
        inside = np.all((partner >= 0) & (partner < side), axis=1)
        j = index[partner[inside, 0], partner[inside, 1], partner[inside, 2]]
        near += int(np.sum(np.abs(np.arange(len(points))[inside] - j) <= window))
        count += int(inside.sum())
    return near / count


def test_morton_keys_of_the_unit_cube_cells_are_z_order():
    corners = np.array(list(itertools.product((0, 1), repeat=3)), dtype=float)[:, ::-1]  # x fastest
    assert morton_keys(corners, 1.0).tolist() == list(range(8))
    # one more level: cell (2, 0, 0) is x bit 1 → key bit 3
    assert morton_keys(np.array([[0.0, 0, 0], [2.0, 0, 0], [0, 2.0, 0], [3.0, 3.0, 3.0]]), 1.0).tolist() == \
        [0, 8, 16, 63]


def test_order_is_a_stable_permutation():
    rng = np.random.default_rng(7)
    points = rng.integers(0, 4, size=(500, 3)).astype(float)  # many ties
    order = morton_order(points, 1.0)
    assert sorted(order.tolist()) == list(range(500))
    keys = morton_keys(points, 1.0)[order]
    assert np.all(np.diff(keys.astype(np.int64)) >= 0)
    for key in np.unique(keys):  # ties keep their input order
        tied = order[keys == key]
        assert np.all(np.diff(tied) > 0)


def test_reorder_moves_every_array_together():
    rng = np.random.default_rng(3)
    n = 200
    cloud = NodeCloud(points=rng.random((n, 3)), volume=np.arange(1.0, n + 1), block=np.arange(n, dtype=np.int32) % 3 + 1,
                      sets={"a": np.arange(n) % 5 == 0, "b": np.arange(n) < 17}, grid_spacing=0.05, dimension=3)
    order = rng.permutation(n)
    out = reorder(cloud, order)
    for k, i in enumerate(order):
        assert np.array_equal(out.points[k], cloud.points[i])
        assert out.volume[k] == cloud.volume[i] and out.block[k] == cloud.block[i]
        assert out.sets["a"][k] == cloud.sets["a"][i] and out.sets["b"][k] == cloud.sets["b"][i]
    assert out.problems() == []


def test_morton_order_restores_locality_of_a_shuffled_lattice():
    """A 24³ lattice, δ = 3dx. Measured (this test's numbers): of the bonds, 24% have their ends
    within 512 indices in the x-fastest order (a z-partner is 576 indices away), 7.3% once
    shuffled, 78% after Morton-sorting the shuffled cloud."""
    dx, side = 1e-3, 24
    points = cubic_lattice(side, dx)
    x_fastest = near_fraction(points, dx)
    shuffled = points[np.random.default_rng(1).permutation(len(points))]
    scattered = near_fraction(shuffled, dx)
    sorted_back = near_fraction(shuffled[morton_order(shuffled, dx)], dx)
    assert scattered < 0.1
    assert x_fastest < 0.3
    assert sorted_back > 0.7


def test_pipeline_clouds_are_written_in_morton_order(meshes):
    for method, dx in (("lattice", 5e-4), ("mesh-nodes", None)):
        cloud = build_node_cloud(meshes["plate"], dimension=2, thickness=1e-3, method=method, dx=dx,
                                 block_names=["plate"], set_layers={})
        keys = morton_keys(cloud.points, cloud.grid_spacing).astype(np.int64)
        assert np.all(np.diff(keys) >= 0), method
        again = space_filling_order(cloud)
        assert np.array_equal(again.points, cloud.points)  # idempotent
