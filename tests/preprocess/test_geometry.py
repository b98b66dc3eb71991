"""Element geometry: simplex splits give exact measures, distances agree with brute force."""
import numpy as np
import pytest

from preprocess.geometry import (element_measure, point_segment_distance, point_triangle_distance,
                                 simplices)

CUBE = np.array([[0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 3, 0], [0, 0, 4], [2, 0, 4], [2, 3, 4], [0, 3, 4]], float)


def test_measures_of_every_shape():
    assert element_measure(CUBE, "hexahedron", np.arange(8)[None]) == pytest.approx([24.0])
    wedge = CUBE[[0, 1, 3, 4, 5, 7]]
    assert element_measure(wedge, "wedge", np.arange(6)[None]) == pytest.approx([12.0])
    pyramid = np.vstack([CUBE[:4], [[1, 1.5, 4]]])
    assert element_measure(pyramid, "pyramid", np.arange(5)[None]) == pytest.approx([8.0])
    assert element_measure(CUBE, "tetra", np.array([[0, 1, 3, 4]])) == pytest.approx([4.0])
    assert element_measure(CUBE, "quad", np.array([[0, 1, 2, 3]])) == pytest.approx([6.0])
    assert element_measure(CUBE, "triangle", np.array([[0, 2, 1]])) == pytest.approx([3.0])  # unsigned
    assert element_measure(CUBE, "line", np.array([[0, 6]])) == pytest.approx([np.sqrt(29.0)])


def test_hexahedron_split_tiles_the_cell():
    conn, owner_type, owner_index, types = simplices({"hexahedron": np.arange(8)[None]}, 3)
    assert conn.shape == (6, 4) and types == ["hexahedron"] and np.all(owner_index == 0)
    rng = np.random.default_rng(0)
    p = rng.random((2000, 3)) * [2, 3, 4]
    inside = np.zeros(len(p), int)
    for tet in conn:
        v = CUBE[tet]
        lam = np.linalg.solve((v[1:] - v[0]).T, (p - v[0]).T).T
        inside += (lam.min(axis=1) >= 0) & (lam.sum(axis=1) <= 1)
    assert np.all(inside == 1)     # every point of the box in exactly one tet


def test_distances_against_brute_force():
    rng = np.random.default_rng(2)
    m = 300
    p, a, b, c = (rng.normal(size=(m, 3)) for _ in range(4))
    t = np.linspace(0, 1, 2001)
    brute = np.min(np.linalg.norm(p[:, None] - (a[:, None] + t[None, :, None] * (b - a)[:, None]), axis=2), axis=1)
    d = point_segment_distance(p, a, b)
    assert np.all(d <= brute + 1e-12) and np.allclose(d, brute, atol=2e-3)
    u, v = np.meshgrid(np.linspace(0, 1, 201), np.linspace(0, 1, 201))
    keep = (u + v) <= 1
    u, v = u[keep], v[keep]
    samples = a[:, None] + u[None, :, None] * (b - a)[:, None] + v[None, :, None] * (c - a)[:, None]
    brute = np.min(np.linalg.norm(p[:, None] - samples, axis=2), axis=1)
    d = point_triangle_distance(p, a, b, c)
    assert np.all(d <= brute + 1e-12) and np.allclose(d, brute, atol=2e-2)
    # a point straight above a triangle's interior: its height
    assert point_triangle_distance(np.array([[0.2, 0.2, 0.7]]), np.zeros((1, 3)), np.array([[1., 0, 0]]),
                                   np.array([[0., 1, 0]])) == pytest.approx([0.7])
