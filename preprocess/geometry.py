"""Vectorised element geometry: simplex splits, measures, barycentric coordinates and distances."""
from __future__ import annotations

import numpy as np

from .mesh import ELEMENT_TYPES

# How the corner nodes of each element shape split into simplices (VTK/meshio corner order).
# The hexahedron uses the 0-6 diagonal (6 tets), the wedge the staircase split (3 tets).
SIMPLEX_SPLIT: dict[int, dict[int, list[list[int]]]] = {
    # dim 0 and 1
    1: {0: [[0]]},
    2: {1: [[0, 1]]},
    # dim 2: 3 corners triangle, 4 corners quad
    3: {2: [[0, 1, 2]]},
    4: {2: [[0, 1, 2], [0, 2, 3]], 3: [[0, 1, 2, 3]]},
    # dim 3: 5 pyramid, 6 wedge, 8 hexahedron
    5: {3: [[0, 1, 2, 4], [0, 2, 3, 4]]},
    6: {3: [[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5]]},
    8: {3: [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]},
}


def simplices(cells: dict[str, np.ndarray], dim: int):
    """Split every element of dimension `dim` into simplices of that dimension (corner nodes only).

    Returns (conn (s, dim+1), owner_type (s,) index into `types`, owner_index (s,) element index
    within cells[type], types: list of the element types involved).
    """
    conns, owner_type, owner_index, types = [], [], [], []
    for ctype, conn in cells.items():
        cdim, corners = ELEMENT_TYPES[ctype]
        if cdim != dim or len(conn) == 0:
            continue
        types.append(ctype)
        corner_conn = conn[:, :corners]
        for local in SIMPLEX_SPLIT[corners][dim]:
            conns.append(corner_conn[:, local])
            owner_type.append(np.full(len(conn), len(types) - 1, dtype=np.int32))
            owner_index.append(np.arange(len(conn), dtype=np.int64))
    if not conns:
        return np.zeros((0, dim + 1), np.int64), np.zeros(0, np.int32), np.zeros(0, np.int64), types
    return np.concatenate(conns), np.concatenate(owner_type), np.concatenate(owner_index), types


def simplex_measure(points: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Unsigned length / area / volume of simplices given by (s, k) connectivity, k = 1..4."""
    k = conn.shape[1]
    if k == 1:
        return np.zeros(len(conn))
    v0 = points[conn[:, 0]]
    if k == 2:
        return np.linalg.norm(points[conn[:, 1]] - v0, axis=1)
    a = points[conn[:, 1]] - v0
    b = points[conn[:, 2]] - v0
    if k == 3:
        return 0.5 * np.linalg.norm(np.cross(a, b), axis=1)
    c = points[conn[:, 3]] - v0
    return np.abs(np.einsum("ij,ij->i", np.cross(a, b), c)) / 6.0


def element_measure(points: np.ndarray, ctype: str, conn: np.ndarray) -> np.ndarray:
    """Unsigned measure of each element (straight-sided: from its corner nodes)."""
    dim, corners = ELEMENT_TYPES[ctype]
    if dim == 0:
        return np.zeros(len(conn))
    total = np.zeros(len(conn))
    for local in SIMPLEX_SPLIT[corners][dim]:
        total += simplex_measure(points, conn[:, :corners][:, local])
    return total


def inverse_maps(points: np.ndarray, conn: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For simplices of full dimension `dim` (2: triangles in the xy plane, 3: tets):
    v0 (s, dim), Tinv (s, dim, dim) with λ_{1..dim} = Tinv (p − v0), and a mask of usable
    (non-degenerate) simplices."""
    v = points[conn][:, :, :dim]                      # (s, dim+1, dim)
    v0 = v[:, 0, :]
    T = np.transpose(v[:, 1:, :] - v0[:, None, :], (0, 2, 1))   # columns are edge vectors
    det = np.linalg.det(T)
    scale = np.max(np.abs(T), axis=(1, 2)) ** dim
    ok = np.abs(det) > 1e-12 * np.maximum(scale, np.finfo(float).tiny)
    Tinv = np.zeros_like(T)
    if np.any(ok):
        Tinv[ok] = np.linalg.inv(T[ok])
    return v0, Tinv, ok


def barycentric_min(p: np.ndarray, v0: np.ndarray, Tinv: np.ndarray) -> np.ndarray:
    """Smallest barycentric coordinate of points p (m, dim) in their simplices (rows aligned)."""
    lam = np.einsum("mij,mj->mi", Tinv, p - v0)
    return np.minimum(lam.min(axis=1), 1.0 - lam.sum(axis=1))


def point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points p (m, 3) to segments [a, b] (rows aligned)."""
    ab = b - a
    ap = p - a
    denom = np.einsum("ij,ij->i", ab, ab)
    t = np.divide(np.einsum("ij,ij->i", ap, ab), denom, out=np.zeros(len(p)), where=denom > 0)
    t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(ap - t[:, None] * ab, axis=1)


def point_triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Distance from points p (m, 3) to triangles abc (rows aligned).

    If the projection of p on the triangle's plane falls inside the triangle, the distance is
    the distance to the plane; otherwise the nearest point lies on an edge.
    """
    ab, ac, ap = b - a, c - a, p - a
    n = np.cross(ab, ac)
    nn = np.einsum("ij,ij->i", n, n)
    good = nn > 0
    # barycentric coordinates of the projection: p' = a + u ab + v ac
    d00 = np.einsum("ij,ij->i", ab, ab)
    d01 = np.einsum("ij,ij->i", ab, ac)
    d11 = np.einsum("ij,ij->i", ac, ac)
    d20 = np.einsum("ij,ij->i", ap, ab)
    d21 = np.einsum("ij,ij->i", ap, ac)
    denom = d00 * d11 - d01 * d01
    safe = np.where(good, denom, 1.0)
    u = (d11 * d20 - d01 * d21) / safe
    v = (d00 * d21 - d01 * d20) / safe
    inside = good & (u >= 0) & (v >= 0) & (u + v <= 1)
    plane = np.abs(np.einsum("ij,ij->i", ap, n)) / np.sqrt(np.where(good, nn, 1.0))
    edges = np.minimum(np.minimum(point_segment_distance(p, a, b), point_segment_distance(p, b, c)),
                       point_segment_distance(p, c, a))
    return np.where(inside, plane, edges)
