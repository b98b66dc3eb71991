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


def sample_entities(mesh_points: np.ndarray, conn: np.ndarray, spacing: float) -> np.ndarray:
    """Points on the entities of `conn` ((m, 1) points, (m, 2) segments, (m, 3) triangles of
    mesh_points), no two neighbours further apart than `spacing`: vertices included."""
    verts = mesh_points[conn]                                  # (m, k, 3)
    k = conn.shape[1]
    if k == 1:
        return verts[:, 0]
    out = [verts.reshape(-1, 3)]
    longest = max(float(np.linalg.norm(verts[:, (i + 1) % k] - verts[:, i], axis=1).max()) for i in range(k))
    n = max(1, int(np.ceil(longest / spacing)))
    if k == 2:
        w = np.linspace(0.0, 1.0, n + 1)
        out.append((verts[:, :1] * (1.0 - w)[None, :, None] + verts[:, 1:2] * w[None, :, None]).reshape(-1, 3))
    else:
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        a, b = i[keep] / n, j[keep] / n
        c = 1.0 - a - b
        out.append((verts[:, 0:1] * a[None, :, None] + verts[:, 1:2] * b[None, :, None]
                    + verts[:, 2:3] * c[None, :, None]).reshape(-1, 3))
    return np.concatenate(out)


def reached_through_body(nodes: np.ndarray, tree: cKDTree, candidates: np.ndarray, entity_points: np.ndarray,
                         dx: float, dimension: int) -> np.ndarray:
    """Of the lattice nodes `candidates` (indices into `nodes`), those whose straight path to the
    nearest point of the entity (sampled as `entity_points`, dx/4 apart) stays inside the body.
    Inside means within half a cell diagonal (0.5·dx·√d) of some lattice node, as every point at
    least dx inside the body is (its cell's centre is then inside too, so a node); the path is
    sampled dx/2 apart from the node up to dx short of the entity, whose nearest node may be up
    to about a cell away when the boundary cuts cells unevenly. A path across a notch, slit or
    hole wider than about two cells meets a sample in the void and fails, so a layer on one notch
    face stops at the notch (issue 16: a 3 mm layer on one face reached across a 1.5 mm notch)."""
    if len(candidates) == 0:
        return candidates
    reach = 0.5 * dx * np.sqrt(dimension) * (1.0 + 1e-6)
    _, nearest = cKDTree(entity_points).query(nodes[candidates])
    start, end = nodes[candidates], entity_points[nearest]
    length = np.linalg.norm(end - start, axis=1)
    count = np.floor(np.maximum(length - dx, 0.0) / (0.5 * dx)).astype(np.int64)
    keep = np.ones(len(candidates), dtype=bool)
    for c in np.unique(count[count > 0]):
        rows = np.flatnonzero(count == c)
        arc = 0.5 * dx * np.arange(1, c + 1)                 # distance from the node along the path
        direction = (end[rows] - start[rows]) / length[rows, None]
        path = start[rows, None, :] + direction[:, None, :] * arc[None, :, None]
        gap, _ = tree.query(path.reshape(-1, 3), distance_upper_bound=reach)
        keep[rows] = np.all(np.isfinite(gap).reshape(len(rows), c), axis=1)
    return candidates[keep]
