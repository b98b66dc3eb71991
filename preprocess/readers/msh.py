"""Gmsh .msh files (format 2 and 4) through meshio, with physical groups recovered by name.

What meshio 5.0 gives: `field_data[name] = [tag, dim]` for every named physical group. For msh4,
`cell_sets[name]` lists, per cell block, the indices of the group's elements (an element may
belong to several groups); `cell_data["gmsh:physical"]` holds only the first tag. For msh2,
`cell_sets` is empty and an element in several groups is written once per group, each copy
with one physical tag: we rebuild the groups from the tags and drop the copies.
"""
from __future__ import annotations

import warnings

import numpy as np

from ..errors import PreprocessError
from ..mesh import ELEMENT_TYPES, Group, Mesh, element_dimension


def _element_nodes_exist(path: str):
    """PreprocessError naming the element and its line if an element of an ASCII .msh (format 2 or
    4) names a node that $Nodes does not define. meshio maps node tags through an array: a tag
    missing between others became -1 and a tag 0 wrapped round to the last node, both silently
    (a binary file is checked after meshio, on the indices it returns)."""
    tags: set[int] = set()
    version, section, expect = None, None, 0
    with open(path, "rb") as stream:
        for number, raw in enumerate(stream, 1):
            line = raw.strip()
            if line.startswith(b"$"):
                section, expect = (None if line.startswith(b"$End") else line[1:].decode("ascii", "replace")), -1
                continue
            if section == "MeshFormat":
                fields = line.split()
                if len(fields) >= 2 and fields[1] != b"0":
                    return   # binary
                version = fields[0] if fields else None
            elif section not in ("Nodes", "Elements") or not line:
                continue
            fields = line.split()
            if expect == -1:       # the section's header line
                expect = 0
                continue
            if version and version.startswith(b"2"):
                if section == "Nodes":
                    tags.add(int(fields[0]))
                else:
                    nodes = fields[3 + int(fields[2]):]
                    _refuse_missing(path, number, fields[0], nodes, tags)
                continue
            # format 4: a block header, then (Nodes) its tags and coordinates, (Elements) its elements
            if expect == 0:
                expect = int(fields[3])
                # 4.1 lists a block's node tags, then their coordinates; 4.0 one "tag x y z" line a node
                block_lines = expect * (2 if section == "Nodes" and version != b"4" and not version.startswith(b"4.0")
                                        else 1)
                position = 0
                continue
            if section == "Nodes":
                if position < expect:
                    tags.add(int(fields[0]))
            else:
                _refuse_missing(path, number, fields[0], fields[1:], tags)
            position += 1
            if position == block_lines:
                expect = 0


def _refuse_missing(path, number, element, nodes, tags):
    for node in nodes:
        if int(node) not in tags:
            raise PreprocessError(f"{path}:{number}: element {element.decode()} names node {node.decode()}, which "
                                  "$Nodes does not define; fix the mesh (export it again)")


def read(path: str) -> Mesh:
    import meshio.gmsh  # imported here so that a missing meshio only matters for .msh files

    try:
        _element_nodes_exist(path)
    except (ValueError, IndexError):
        pass   # a malformed file: meshio says what is wrong with it below
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m = meshio.gmsh.read(path)  # meshio.read prints a ReadError and calls sys.exit(1)
    except Exception as err:  # meshio raises many types (ReadError, ValueError, IndexError...)
        reason = str(err) or f"{type(err).__name__} (meshio gives no reason)"
        raise PreprocessError(f"{path}: cannot read as a gmsh .msh file: {reason}") from err

    blocks = []  # (type, connectivity, physical tags or None)
    physical = m.cell_data.get("gmsh:physical")
    for i, block in enumerate(m.cells):
        if block.type not in ELEMENT_TYPES:
            raise PreprocessError(f"{path}: element type '{block.type}' is not supported; supported: "
                                  f"{', '.join(ELEMENT_TYPES)}")
        tags = None if physical is None else np.asarray(physical[i])
        conn = np.asarray(block.data, dtype=np.int64)
        bad = np.nonzero((conn < 0) | (conn >= len(m.points)))[0]
        if len(bad):
            raise PreprocessError(f"{path}: {block.type} element {bad[0] + 1} of element block {i + 1} names a node "
                                  "that $Nodes does not define; fix the mesh (export it again)")
        blocks.append((block.type, conn, tags))

    names = {str(name): (int(v[0]), int(v[1])) for name, v in m.field_data.items()
             if np.asarray(v).size >= 2}
    set_names = [k for k in m.cell_sets if not k.startswith("gmsh:")]

    # Concatenate blocks of the same type; remember each block's offset in the concatenation.
    cells: dict[str, list[np.ndarray]] = {}
    offsets = []
    for ctype, conn, _ in blocks:
        offsets.append(sum(len(c) for c in cells.get(ctype, [])))
        cells.setdefault(ctype, []).append(conn)
    cells_cat = {t: np.concatenate(v) for t, v in cells.items()}

    members: dict[str, dict[str, list[np.ndarray]]] = {name: {} for name in names}
    if set_names:  # msh4
        for name in set_names:
            if name not in members:
                continue
            for i, idx in enumerate(m.cell_sets[name]):
                if idx is None or len(idx) == 0:
                    continue
                ctype = blocks[i][0]
                members[name].setdefault(ctype, []).append(np.asarray(idx, np.int64) + offsets[i])
    else:  # msh2 (or msh4 without groups): physical tags per element, (tag, dim) -> name
        by_tag = {(tag, dim): name for name, (tag, dim) in names.items()}
        for i, (ctype, conn, tags) in enumerate(blocks):
            if tags is None:
                continue
            dim = element_dimension(ctype)
            for tag in np.unique(tags):
                name = by_tag.get((int(tag), dim))
                if name is not None:
                    idx = np.nonzero(tags == tag)[0] + offsets[i]
                    members[name].setdefault(ctype, []).append(idx)

    # Drop duplicated elements (msh2 writes an element once per physical group).
    remap = {}
    for ctype, conn in cells_cat.items():
        unique, first, inverse = np.unique(conn, axis=0, return_index=True, return_inverse=True)
        if len(unique) < len(conn):
            order = np.sort(first)                      # keep file order of first occurrences
            new_index = np.empty(len(unique), np.int64)
            new_index[np.argsort(first)] = np.arange(len(unique))
            cells_cat[ctype] = conn[order]
            remap[ctype] = new_index[inverse.ravel()]

    groups = {}
    for name, (tag, dim) in names.items():
        gcells = {}
        for ctype, parts in members[name].items():
            idx = np.concatenate(parts)
            if ctype in remap:
                idx = remap[ctype][idx]
            gcells[ctype] = np.unique(idx)
        groups[name] = Group(name=name, dim=dim, cells=gcells)

    points = np.asarray(m.points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise PreprocessError(f"{path}: points have shape {points.shape}, expected (n, 3)")
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return Mesh(path=path, points=points, cells=cells_cat, groups=groups)
