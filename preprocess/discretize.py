"""Mesh → NodeCloud: the lattice and mesh-nodes discretizations, blocks and node sets.

Blocks. The caller passes the ordered block names (the case's materials). Each must name a
physical group of the top dimension (surfaces in 2D, volumes in 3D); block ids are 1-based
positions in that list. Exception: if the mesh has exactly one top-dimension group or none and
one block name is given, every node belongs to that block whatever the group is called. Two
blocks may not share elements. A lattice node takes the block of the element it lies in; a mesh
node shared by elements of several blocks takes the first of those blocks in the given order.
A node in no block is an error.

Node sets. Every named physical group becomes a node set:
  - a group of the top dimension: the lattice nodes inside its elements, or the mesh nodes of
    its elements;
  - a lower-dimension group (curves, surfaces in 3D, points; UNV node groups): the nodes within
    distance `layer` of its elements (segments, triangles, points), with layer = set_layers[name]
    if given, else for mesh-nodes exactly the nodes of the group, and for a lattice
    0.5·dx·√(d − k)·(1 + 1e-6) for a k-dimensional group in d dimensions: 0.5·dx for a curve
    in 2D or a surface in 3D, so that the first row of cell-centred nodes along the entity is
    taken; the same row along an edge of a box in 3D (√2/2·dx) and the nearest corner node of
    a point (√d/2·dx).
    The distance is measured to the whole group, its end points included: a layer on an open
    curve has round caps of radius `layer` around the curve's ends (a layer on a notch face also
    takes the nodes ahead of the notch tip within `layer`). On a lattice, a layer wider than dx is
    measured through the body: a node counts only if the straight path to its nearest point of the
    group stays inside the body (locate.reached_through_body), so a layer on one face of a notch or
    of a slit does not reach across the gap to the nodes on the other side.
"""
from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial import cKDTree

from .cloud import SET_NAME, NodeCloud
from .errors import PreprocessError, PreprocessWarning
from .geometry import element_measure, simplices
from .locate import (lattice_axes, lattice_points, locate_lattice, near_entities, reached_through_body,
                     sample_entities)
from .mesh import Mesh, element_dimension

METHODS = ("lattice", "mesh-nodes")


# Beyond this a squared distance overflows (the solver's node-file reader has the same limit), and a
# lattice box of more cells than MAX_LATTICE_CELLS is no case a machine here could run (issue 17,
# item 9: a 1e300 coordinate ended in a numpy traceback).
MAX_COORDINATE = 1e150      # m
MAX_LATTICE_CELLS = 1e10


def default_lattice_layer(dx: float, dimension: int, group_dim: int) -> float:
    """Distance that takes the first row of cell-centred nodes around a group (module docstring)."""
    return 0.5 * dx * np.sqrt(dimension - group_dim) * (1 + 1e-6)


def _fmt(p) -> str:
    return "(" + ", ".join(f"{v:.6g}" for v in p) + ")"


def discretize(mesh: Mesh, *, dimension: int, thickness: float | None, method: str, dx: float | None,
               block_names: list[str], set_layers: dict[str, float],
               lattice_origin=None) -> NodeCloud:
    """Turn `mesh` into a NodeCloud (see the module docstring for blocks and sets).

    lattice_origin: a point [x, y(, z)] of the lattice, so that its nodes sit at origin + k·dx
    (k integer), as LAMMPS's `lattice` puts atoms at k·a; None: cell centres of the mesh's
    bounding box."""
    path = mesh.path
    if method not in METHODS:
        raise PreprocessError(f"{path}: unknown discretization method '{method}'; known: {', '.join(METHODS)}")
    if dimension not in (2, 3):
        raise PreprocessError(f"{path}: dimension must be 2 or 3, not {dimension}")
    if dimension == 2 and not (thickness is not None and thickness > 0):
        raise PreprocessError(f"{path}: a 2D case needs a thickness > 0 (node volume = area x thickness)")
    if method == "lattice" and not (dx is not None and dx > 0):
        raise PreprocessError(f"{path}: the lattice method needs a spacing dx > 0")
    if not block_names:
        raise PreprocessError(f"{path}: no block names given (one material per block)")
    points = _check_points(mesh, dimension)
    top = {t: c for t, c in mesh.cells.items() if element_dimension(t) == dimension and len(c)}
    measures = _measures(mesh, points, top, dimension, thickness)
    elem_block = _element_blocks(mesh, top, dimension, block_names)

    if method == "lattice":
        cloud, where = _lattice(mesh, points, top, dimension, dx, thickness, elem_block, lattice_origin)
    else:
        cloud, where = _mesh_nodes(mesh, points, top, dimension, measures, elem_block)
    cloud.sets = _node_sets(mesh, points, top, cloud, where, method, dx, set_layers)
    problems = cloud.problems()
    if problems:  # should not happen; a safety net before anything is written
        raise PreprocessError(f"{path}: internal error, invalid node cloud: {'; '.join(problems)}")
    return cloud


def _check_points(mesh: Mesh, dimension: int) -> np.ndarray:
    path = mesh.path
    points = np.asarray(mesh.points, dtype=np.float64)
    if len(points) == 0 or mesh.top_dimension() < 0:
        raise PreprocessError(f"{path}: the mesh is empty ({len(points)} nodes, no elements); "
                              f"was the geometry meshed?")
    bad = ~np.all(np.isfinite(points), axis=1)
    if np.any(bad):
        i = int(np.nonzero(bad)[0][0])
        raise PreprocessError(f"{path}: {int(bad.sum())} node(s) have NaN or infinite coordinates "
                              f"(first: node index {i}); fix the mesh")
    far = np.abs(points) > MAX_COORDINATE
    if np.any(far):
        i = int(np.nonzero(np.any(far, axis=1))[0][0])
        raise PreprocessError(f"{path}: {int(np.any(far, axis=1).sum())} node(s) lie beyond ±{MAX_COORDINATE:g} m "
                              f"(first: node index {i} at {_fmt(points[i])}); coordinates are in metres: "
                              "fix the mesh")
    top = mesh.top_dimension()
    if top > dimension:
        raise PreprocessError(f"{path}: the mesh has {top}D elements but the case is {dimension}D; "
                              f"mesh it with gmsh -{dimension} or change the case's dimension")
    if top < dimension:
        raise PreprocessError(f"{path}: the mesh has no {dimension}D elements (its highest dimension is "
                              f"{top}); mesh it with gmsh -{dimension} and give the "
                              f"{'surfaces' if dimension == 2 else 'volumes'} a physical group")
    if dimension == 2:
        size = float(np.max(np.ptp(points, axis=0))) or 1.0
        off = np.abs(points[:, 2]) > 1e-9 * size
        if np.any(off):
            i = int(np.nonzero(off)[0][0])
            raise PreprocessError(f"{path}: a 2D mesh must lie in the plane z = 0; {int(off.sum())} node(s) "
                                  f"do not, e.g. {_fmt(points[i])}")
        points = points.copy()
        points[:, 2] = 0.0
    return points


def _measures(mesh: Mesh, points, top, dimension, thickness) -> dict[str, np.ndarray]:
    """Element measures of the top dimension (× thickness in 2D); warn on degenerate elements."""
    factor = thickness if dimension == 2 else 1.0
    measures = {t: element_measure(points, t, c) * factor for t, c in top.items()}
    total = sum(float(m.sum()) for m in measures.values())
    if not total > 0:
        raise PreprocessError(f"{mesh.path}: the {dimension}D elements have total "
                              f"{'area' if dimension == 2 else 'volume'} {total:g}; the mesh is degenerate")
    tiny = 1e-12 * total
    degenerate = sum(int(np.sum(m <= tiny)) for m in measures.values())
    if degenerate:
        warnings.warn(f"{mesh.path}: {degenerate} degenerate {dimension}D element(s) with zero "
                      f"{'area' if dimension == 2 else 'volume'}", PreprocessWarning, stacklevel=3)
    return measures


def missing_blocks(mesh: Mesh, dimension: int, block_names: list[str]) -> dict[str, str]:
    """Block name → why it names no top-dimension physical group of the mesh ({} when every block
    does, or when one block is given and the mesh has at most one top-dimension group: the module
    docstring's exception). `make check` asks this before preprocessing."""
    top_groups = [g for g in mesh.groups.values() if g.dim == dimension]
    if len(block_names) == 1 and len(top_groups) <= 1:
        return {}
    missing = {}
    for n in block_names:
        if n not in mesh.groups:
            missing[n] = f"block '{n}' is not a physical group of the mesh"
        elif mesh.groups[n].dim != dimension:
            missing[n] = f"block '{n}' is a {mesh.groups[n].dim}D physical group, not a {dimension}D one"
    return missing


def _element_blocks(mesh: Mesh, top, dimension, block_names) -> dict[str, np.ndarray]:
    """1-based block id of every top-dimension element (0: in no block)."""
    path = mesh.path
    top_groups = [g for g in mesh.groups.values() if g.dim == dimension]
    elem_block = {t: np.zeros(len(c), dtype=np.int32) for t, c in top.items()}
    if len(block_names) == 1 and len(top_groups) <= 1:
        for t in elem_block:
            elem_block[t][:] = 1
        return elem_block
    missing = missing_blocks(mesh, dimension, block_names)
    if missing:
        err = PreprocessError(f"{path}: {'; '.join(missing.values())}; the {dimension}D groups are: "
                              f"{', '.join(g.name for g in top_groups) or 'none'}")
        # What the driver needs to point at the case file's materials.<name> line instead.
        err.missing_blocks = missing
        err.top_groups = [g.name for g in top_groups]
        raise err
    for bid, name in enumerate(block_names, start=1):
        for t, idx in mesh.groups[name].cells.items():
            if t not in elem_block:
                continue
            taken = elem_block[t][idx]
            if np.any(taken):
                other = block_names[int(taken[taken > 0][0]) - 1]
                raise PreprocessError(f"{path}: blocks '{other}' and '{name}' share "
                                      f"{int(np.sum(taken > 0))} element(s); a block's physical group "
                                      f"must not overlap another block's")
            elem_block[t][idx] = bid
    return elem_block


def _no_block_error(path, points, count):
    raise PreprocessError(f"{path}: {count} node(s) lie in no block, e.g. at {_fmt(points[0])}; "
                          f"add their elements to the physical group of a block (a material of the case)")


def _lattice(mesh, points, top, dimension, dx, thickness, elem_block, lattice_origin=None):
    """Cell-centred lattice nodes inside the top-dimension elements (or, with lattice_origin, the
    lattice through that point). Returns the cloud and, per node, (type id, element index, types)
    of the element that holds it."""
    path = mesh.path
    used = np.unique(np.concatenate([c.ravel() for c in top.values()]))
    lo, hi = points[used].min(axis=0), points[used].max(axis=0)
    cells = float(np.prod(np.floor((hi[:dimension] - lo[:dimension]) / dx) + 1.0))
    if not cells <= MAX_LATTICE_CELLS:
        raise PreprocessError(f"{path}: the lattice with dx = {dx:g} m over the mesh's bounding box {_fmt(lo)} to "
                              f"{_fmt(hi)} would have {cells:.3g} cells, more than {MAX_LATTICE_CELLS:.0e}; "
                              "use a larger dx, or check the mesh for a node far from the others")
    first = None  # lattice index of cell 0 per axis, counted from lattice_origin
    if lattice_origin is not None:
        anchor = np.asarray(lattice_origin, dtype=np.float64).ravel()
        if len(anchor) != dimension:
            raise PreprocessError(f"{path}: the lattice origin needs {dimension} coordinates, got {len(anchor)}")
        # Cells of width dx centred on anchor + k·dx; cell `first` holds lo, and the cells from it
        # cover [lo, hi] as the cell-centred lattice does.
        first = np.floor((lo[:dimension] - anchor) / dx + 0.5).astype(np.int64)
        corner = anchor + (first - 0.5) * dx
        _, shape = lattice_axes(corner, hi[:dimension], dx)
        origin = corner
    else:
        origin, shape = lattice_axes(lo[:dimension], hi[:dimension], dx)
    origin = np.concatenate([origin, np.zeros(3 - dimension)])
    conn, owner_type, owner_index, types = simplices(top, dimension)
    flat, simplex = locate_lattice(points, conn, dimension, origin, dx, shape)
    if len(flat) == 0:
        raise PreprocessError(f"{path}: no lattice node with dx = {dx:g} m falls inside the mesh "
                              f"(bounding box {_fmt(lo)} to {_fmt(hi)}); use a smaller dx")
    pts = lattice_points(flat, origin, dx, shape, dimension)
    if first is not None:  # exactly anchor + k·dx (LAMMPS: k·a for origin 0), not corner + (i + ½)·dx
        rem = flat
        for a in range(dimension):
            pts[:, a] = anchor[a] + (first[a] + rem % shape[a]) * dx
            rem = rem // shape[a]
    etype, eidx = owner_type[simplex], owner_index[simplex]
    block = np.zeros(len(flat), dtype=np.int32)
    for ti, t in enumerate(types):
        m = etype == ti
        block[m] = elem_block[t][eidx[m]]
    if np.any(block == 0):
        _no_block_error(path, pts[block == 0], int(np.sum(block == 0)))
    volume = np.full(len(flat), dx ** dimension * (thickness if dimension == 2 else 1.0))
    cloud = NodeCloud(points=pts, volume=volume, block=block, sets={}, grid_spacing=float(dx),
                      dimension=dimension)
    return cloud, (etype, eidx, types)


def _mesh_nodes(mesh, points, top, dimension, measures, elem_block):
    """The mesh's own nodes used by top-dimension elements, volumes lumped equally to each
    element's nodes. Returns the cloud and the map mesh node -> cloud node (−1: not a node)."""
    path = mesh.path
    n = len(points)
    volume = np.zeros(n)
    block = np.full(n, np.iinfo(np.int32).max, dtype=np.int64)
    for t, conn in top.items():
        k = conn.shape[1]
        volume += np.bincount(conn.ravel(), weights=np.repeat(measures[t] / k, k), minlength=n)
        eb = np.where(elem_block[t] > 0, elem_block[t], np.iinfo(np.int32).max)
        np.minimum.at(block, conn.ravel(), np.repeat(eb, k))
    used = np.unique(np.concatenate([c.ravel() for c in top.values()]))
    index = np.full(n, -1, dtype=np.int64)
    index[used] = np.arange(len(used))
    pts, volume, block = points[used], volume[used], block[used]
    none = block == np.iinfo(np.int32).max
    if np.any(none):
        _no_block_error(path, pts[none], int(none.sum()))
    if np.any(volume <= 0):
        bad = volume <= 0
        raise PreprocessError(f"{path}: {int(bad.sum())} node(s) belong only to degenerate elements and "
                              f"get no volume, e.g. at {_fmt(pts[bad][0])}; fix the mesh")
    if len(pts) < 2:
        raise PreprocessError(f"{path}: the mesh has a single node; nothing to discretize")
    size = float(np.max(np.ptp(pts, axis=0)))
    dist, nearest = cKDTree(pts).query(pts, k=2)
    dup = dist[:, 1] <= 1e-12 * size
    if np.any(dup):
        i = int(np.nonzero(dup)[0][0])
        raise PreprocessError(f"{path}: {int(dup.sum())} node(s) coincide with another node (within "
                              f"1e-12 x the model size), e.g. at {_fmt(pts[i])}; merge duplicate nodes "
                              f"(gmsh: Coherence Mesh;)")
    cloud = NodeCloud(points=pts, volume=volume, block=block.astype(np.int32), sets={},
                      grid_spacing=float(np.median(dist[:, 1])), dimension=dimension)
    return cloud, index


def _entities(mesh: Mesh, name: str) -> list[np.ndarray]:
    """A group's elements as simplices of their own dimension (points, segments, triangles),
    plus its explicit nodes as points."""
    group = mesh.groups[name]
    out = []
    for d in (0, 1, 2):
        cells = {t: mesh.cells[t][idx] for t, idx in group.cells.items()
                 if element_dimension(t) == d and len(idx)}
        conn = simplices(cells, d)[0]
        if len(conn):
            out.append(conn)
    if len(group.explicit_nodes):
        out.append(np.asarray(group.explicit_nodes, dtype=np.int64)[:, None])
    return out


def _node_sets(mesh, points, top, cloud, where, method, dx, set_layers) -> dict[str, np.ndarray]:
    path = mesh.path
    dimension = cloud.dimension
    unknown = [n for n in set_layers if n not in mesh.groups]
    if unknown:
        raise PreprocessError(f"{path}: layer given for {', '.join(repr(n) for n in unknown)}, which "
                              f"{'is not a physical group' if len(unknown) == 1 else 'are not physical groups'} "
                              f"of the mesh; groups: {', '.join(mesh.groups) or 'none'}")
    sets = {}
    tree = None
    for name, group in mesh.groups.items():
        if not SET_NAME.match(name):
            raise PreprocessError(f"{path}: physical group '{name}' is not a valid node-set name "
                                  f"([A-Za-z_][A-Za-z0-9_]*, e.g. 'left_edge'); rename it")
        if group.dim == dimension:
            if name in set_layers:
                raise PreprocessError(f"{path}: node set '{name}' is a {dimension}D group; a layer only "
                                      f"applies to lower-dimension groups (curves, surfaces in 3D, points)")
            members = {t: np.zeros(len(c), dtype=bool) for t, c in top.items()}
            for t, idx in group.cells.items():
                if t in members:
                    members[t][idx] = True
            if method == "lattice":
                etype, eidx, types = where
                mask = np.zeros(len(cloud.volume), dtype=bool)
                for ti, t in enumerate(types):
                    m = etype == ti
                    mask[m] = members[t][eidx[m]]
            else:
                mask = np.zeros(len(cloud.volume), dtype=bool)
                for t, conn in top.items():
                    nodes = where[conn[members[t]].ravel()]
                    mask[nodes[nodes >= 0]] = True
        else:
            layer = set_layers.get(name)
            if layer is not None and not (layer >= 0):
                raise PreprocessError(f"{path}: the layer of node set '{name}' must be >= 0, not {layer}")
            if layer is None and method == "mesh-nodes":
                nodes = where[mesh.group_nodes(name)]
                mask = np.zeros(len(cloud.volume), dtype=bool)
                mask[nodes[nodes >= 0]] = True
            else:
                if layer is None:
                    layer = default_lattice_layer(dx, dimension, group.dim)
                if tree is None:
                    tree = cKDTree(cloud.points)
                mask = np.zeros(len(cloud.volume), dtype=bool)
                entities = _entities(mesh, name)
                for conn in entities:
                    mask |= near_entities(cloud.points, tree, points, conn, layer)
                if method == "lattice" and layer > dx:
                    # measured through the body: not across a notch or a hole (module docstring)
                    samples = np.concatenate([sample_entities(points, conn, 0.25 * dx) for conn in entities])
                    inside = reached_through_body(cloud.points, tree, np.flatnonzero(mask), samples, dx, dimension)
                    mask = np.zeros(len(cloud.volume), dtype=bool)
                    mask[inside] = True
        if not np.any(mask):
            raise PreprocessError(f"{path}: physical group '{name}' ({group.dim}D) holds no node of the "
                                  f"{method} discretization; "
                                  + ("give it a larger layer (node_sets.{name}.layer) or a smaller dx"
                                     .replace("{name}", name) if group.dim < dimension else
                                     "its elements are too small for the lattice; use a smaller dx"))
        sets[name] = mask
    return sets
