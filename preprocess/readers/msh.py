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


def read(path: str) -> Mesh:
    import meshio  # imported here so that a missing meshio only matters for .msh files

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m = meshio.read(path, file_format="gmsh")
    except Exception as err:  # meshio raises many types (ReadError, ValueError, IndexError...)
        raise PreprocessError(f"{path}: cannot read as a gmsh .msh file: {err}") from err

    blocks = []  # (type, connectivity, physical tags or None)
    physical = m.cell_data.get("gmsh:physical")
    for i, block in enumerate(m.cells):
        if block.type not in ELEMENT_TYPES:
            raise PreprocessError(f"{path}: element type '{block.type}' is not supported; supported: "
                                  f"{', '.join(ELEMENT_TYPES)}")
        tags = None if physical is None else np.asarray(physical[i])
        blocks.append((block.type, np.asarray(block.data, dtype=np.int64), tags))

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
