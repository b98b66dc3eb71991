"""Bucketed searches: which lattice points lie in which simplex, which nodes lie near an entity.

Lattice points are themselves buckets: for a simplex we enumerate only the lattice points of its
bounding box (a box of integer indices), so the work is proportional to the summed bounding-box
volumes, about (2 to 6) × the number of nodes, and is done in vectorised chunks.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .geometry import (barycentric_min, inverse_maps, point_segment_distance,
                       point_triangle_distance)

CHUNK = 1 << 21          # candidate (point, simplex) pairs per vectorised batch
INSIDE_TOL = 1e-9        # barycentric tolerance: points on a face count as inside


def lattice_axes(lo: np.ndarray, hi: np.ndarray, dx: float) -> tuple[np.ndarray, list[int]]:
    """Cell-centred lattice over the box [lo, hi]: origin and number of cells per axis
    (x_i = lo + (i + ½) dx, i = 0..n−1, n = ⌈(hi − lo)/dx⌉)."""
    n = [max(1, int(np.ceil((h - l) / dx * (1 - 1e-12)))) for l, h in zip(lo, hi)]
    return np.asarray(lo, dtype=np.float64), n


def _boxes(vmin, vmax, origin, dx, shape):
    """Index boxes [ilo, ihi] (inclusive) of lattice points within each simplex's bounding box."""
    shape = np.asarray(shape)
    ilo = np.ceil((vmin - origin) / dx - 0.5 - 1e-9).astype(np.int64)
    ihi = np.floor((vmax - origin) / dx - 0.5 + 1e-9).astype(np.int64)
    ilo = np.clip(ilo, 0, shape - 1)
    ihi = np.clip(ihi, -1, shape - 1)
    return ilo, ihi


def _split_boxes(owner, ilo, ihi, limit):
    """Split boxes holding more than `limit` points along their longest axis until none does."""
    done_o, done_lo, done_hi = [], [], []
    while len(owner):
        ext = np.maximum(ihi - ilo + 1, 0)
        count = np.prod(ext, axis=1)
        small = count <= limit
        done_o.append(owner[small]), done_lo.append(ilo[small]), done_hi.append(ihi[small])
        owner, ilo, ihi, ext = owner[~small], ilo[~small], ihi[~small], ext[~small]
        if not len(owner):
            break
        axis = np.argmax(ext, axis=1)
        rows = np.arange(len(owner))
        mid = ilo[rows, axis] + ext[rows, axis] // 2
        lo2, hi1 = ilo.copy(), ihi.copy()
        hi1[rows, axis] = mid - 1
        lo2[rows, axis] = mid
        owner = np.concatenate([owner, owner])
        ilo = np.concatenate([ilo, lo2])
        ihi = np.concatenate([hi1, ihi])
    return np.concatenate(done_o), np.concatenate(done_lo), np.concatenate(done_hi)


def locate_lattice(points: np.ndarray, conn: np.ndarray, dim: int, origin: np.ndarray, dx: float,
                   shape: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Lattice points inside the simplices `conn` (triangles in the xy plane for dim 2, tets for 3).

    Returns (flat lattice indices, sorted; index of the containing simplex for each). A point
    inside several simplices (on a shared face, within tolerance) takes the one it is deepest in.
    """
    total = int(np.prod(shape))
    best_score = np.full(total, -np.inf)
    best_simplex = np.full(total, -1, dtype=np.int64)
    if len(conn) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    v0, Tinv, ok = inverse_maps(points, conn, dim)
    corners = points[conn][:, :, :dim]
    ilo, ihi = _boxes(corners.min(axis=1), corners.max(axis=1), origin[:dim], dx, shape[:dim])
    owner = np.nonzero(ok)[0]
    owner, ilo, ihi = _split_boxes(owner, ilo[owner], ihi[owner], CHUNK)
    ext = np.maximum(ihi - ilo + 1, 0)
    count = np.prod(ext, axis=1)
    keep = count > 0
    owner, ilo, ext, count = owner[keep], ilo[keep], ext[keep], count[keep]
    strides = np.cumprod([1] + list(shape[:dim - 1]))        # flat = i + nx j + nx ny k
    # group boxes into batches of at most CHUNK candidates
    cum = np.cumsum(count)
    batch_of = (cum - 1) // CHUNK
    starts = np.searchsorted(batch_of, np.arange(batch_of[-1] + 1 if len(batch_of) else 0))
    bounds = list(starts) + [len(owner)]
    for b in range(len(bounds) - 1):
        s = slice(bounds[b], bounds[b + 1])
        o, lo, ex, c = owner[s], ilo[s], ext[s], count[s]
        if not len(o):
            continue
        item = np.repeat(np.arange(len(o)), c)
        k = np.arange(int(c.sum())) - np.repeat(np.cumsum(c) - c, c)
        idx = np.empty((len(k), dim), dtype=np.int64)
        rem = k
        for a in range(dim):
            e = ex[item, a]
            idx[:, a] = lo[item, a] + rem % e
            rem = rem // e
        p = origin[:dim] + (idx + 0.5) * dx
        simplex = o[item]
        score = barycentric_min(p, v0[simplex], Tinv[simplex])
        inside = score >= -INSIDE_TOL
        flat = idx[inside] @ strides
        score, simplex = score[inside], simplex[inside]
        order = np.lexsort((-score, flat))
        flat, score, simplex = flat[order], score[order], simplex[order]
        first = np.ones(len(flat), dtype=bool)
        first[1:] = flat[1:] != flat[:-1]
        flat, score, simplex = flat[first], score[first], simplex[first]
        better = score > best_score[flat]
        best_score[flat[better]] = score[better]
        best_simplex[flat[better]] = simplex[better]
    found = np.nonzero(best_simplex >= 0)[0]
    return found, best_simplex[found]


def lattice_points(flat: np.ndarray, origin: np.ndarray, dx: float, shape: list[int], dim: int) -> np.ndarray:
    """Coordinates (n, 3) of lattice points from flat indices (z = 0 in 2D)."""
    pts = np.zeros((len(flat), 3))
    rem = flat
    for a in range(dim):
        pts[:, a] = origin[a] + (rem % shape[a] + 0.5) * dx
        rem = rem // shape[a]
    return pts


def near_entities(nodes: np.ndarray, tree: cKDTree, mesh_points: np.ndarray, conn: np.ndarray,
                  layer: float, batch: int = 4096) -> np.ndarray:
    """Mask of `nodes` within distance `layer` of any entity in `conn`: (m, 1) points, (m, 2)
    segments or (m, 3) triangles of mesh_points. A KD-tree of the nodes gives the candidates
    (within layer + circumradius of each entity's centroid); exact distances decide."""
    mask = np.zeros(len(nodes), dtype=bool)
    if len(conn) == 0:
        return mask
    k = conn.shape[1]
    for start in range(0, len(conn), batch):
        c = conn[start:start + batch]
        verts = mesh_points[c]                               # (b, k, 3)
        centre = verts.mean(axis=1)
        radius = np.sqrt(((verts - centre[:, None, :]) ** 2).sum(axis=2).max(axis=1))
        hits = tree.query_ball_point(centre, radius + layer)
        lengths = np.fromiter((len(h) for h in hits), dtype=np.int64, count=len(hits))
        if lengths.sum() == 0:
            continue
        node = np.concatenate([np.asarray(h, dtype=np.int64) for h in hits])
        ent = np.repeat(np.arange(len(c)), lengths)
        todo = ~mask[node]                                  # skip nodes already in the set
        node, ent = node[todo], ent[todo]
        p = nodes[node]
        if k == 1:
            d = np.linalg.norm(p - verts[ent, 0], axis=1)
        elif k == 2:
            d = point_segment_distance(p, verts[ent, 0], verts[ent, 1])
        else:
            d = point_triangle_distance(p, verts[ent, 0], verts[ent, 1], verts[ent, 2])
        mask[node[d <= layer]] = True
    return mask
