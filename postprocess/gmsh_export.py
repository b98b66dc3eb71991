"""Gmsh views of the results, written by our own code:

- results.msh: MSH 4.1 ASCII. $Entities: one point entity per block (physical group = the block,
  named after it) that holds the block's nodes and their 1-node point elements (type 15, so that
  Gmsh draws point data), and two empty point entities at the lower and upper corners of the cloud's
  bounding box. Gmsh frames a view on the model's bounding box, the union of its entities' boxes,
  and a point entity's box is its one point: without the corners a one-block cloud opened zoomed
  on a dot (issue 16). Then one $NodeData block per frame for every point array the frame has
  (displacement, velocity, damage, block, … in the frame's order: a scalar view for 1 component, a
  vector view for 3, a tensor view for 9, a 2-component array padded with a zero z, any other count
  one scalar view `name[k]` per component), tagged with the frame's time and index, so that Gmsh
  animates them (Gmsh merges blocks of the same name into the time steps of one view).
  Tools → Options → View → "Displacement" display of `displacement` warps the body.
- damage_final.pos: Gmsh's parsed format, one scalar point SP(x,y,z){φ} per node, its colour range
  fixed to 0…1, and, if bonds broke, one line SL per broken bond in a second view drawn thin and
  grey without a legend (its values are a constant 1, whose legend read "1 1 1"). Gmsh prints these
  as vector (PDF/SVG/EPS) images.
Both are written under a temporary name and renamed into place.
"""
from __future__ import annotations

from typing import Iterable, Iterator

import numpy as np

from pipeline.atomic import atomic_path
from .errors import PostprocessError
from .series import Frame

POINT_ELEMENT = 15  # Gmsh's 1-node point
CHUNK = 50000       # rows formatted per call, to bound memory on large clouds


def _real(precision: int | None) -> str:
    """%r writes Python's shortest representation that reads back to the same float64."""
    return "%r" if precision is None else f"%.{precision}g"


def _write_rows(stream, first_columns: np.ndarray | None, values: np.ndarray, precision: int | None):
    """Rows 'tag v1 v2 …' with integers in the first column and reals after it, or rows of reals
    only when `first_columns` is None."""
    k = values.shape[1]
    real = " ".join([_real(precision)] * k) + "\n"
    if first_columns is None:
        for start in range(0, len(values), CHUNK):
            block = values[start:start + CHUNK]
            stream.write((real * len(block)) % tuple(block.ravel().tolist()))
        return
    row = "%d " + real
    for start in range(0, len(values), CHUNK):
        tags = first_columns[start:start + CHUNK]
        block = values[start:start + CHUNK]
        flat = np.empty((len(block), k + 1), dtype=object)
        flat[:, 0] = tags.tolist()
        flat[:, 1:] = block.tolist()
        stream.write((row * len(block)) % tuple(flat.ravel().tolist()))


def _node_data(stream, name: str, time: float, index: int, values: np.ndarray, precision: int | None):
    tags = np.arange(1, len(values) + 1)
    stream.write(f'$NodeData\n1\n"{name}"\n1\n{float(time)!r}\n3\n{index}\n{values.shape[1]}\n{len(values)}\n')
    _write_rows(stream, tags, values, precision)
    stream.write("$EndNodeData\n")


def gmsh_views(point_data: dict, n: int) -> Iterator[tuple[str, np.ndarray]]:
    """(view name, (n, 1 | 3 | 9) float64 values) for every point array, in the frame's order."""
    for name, values in point_data.items():
        values = np.asarray(values, dtype=np.float64).reshape(n, -1)
        k = values.shape[1]
        if k in (1, 3, 9):
            yield name, values
        elif k == 2:  # a vector of a 2D frame: Gmsh's vectors have 3 components
            yield name, np.column_stack([values, np.zeros(n)])
        else:
            for c in range(k):
                yield f"{name}[{c}]", values[:, c:c + 1]


def _runs(block: np.ndarray) -> list[tuple[int, int, int]]:
    """(block, first, end) of each maximal run of consecutive nodes first..end-1 in one block."""
    starts = np.concatenate(([0], np.flatnonzero(np.diff(block)) + 1))
    ends = np.concatenate((starts[1:], [len(block)]))
    return [(int(block[a]), int(a), int(b)) for a, b in zip(starts, ends)]


def write_results_msh(path: str, frames: Iterable[tuple[int, float, Frame]], *,
                      block_names: dict | None = None, precision: int | None = None) -> int:
    """Write results.msh from (frame index, time, frame) triples, streaming one frame at a time.

    The nodes are the first frame's points (node tag = index + 1); every frame must have as many.
    Each node and its point element (element tag = node tag) lie on the point entity of its block
    (PointData `block`, 1 if absent), which is physical group `block`, named after `block_names`
    {id: name} in $PhysicalNames when given. Returns the number of frames written.
    Reals are written with `precision` significant digits, or (None, the default) in the shortest
    form that reads back to the same float64, so the values round-trip exactly.
    """
    frames = iter(frames)
    try:
        index, time, frame = next(frames)
    except StopIteration:
        raise PostprocessError(f"{path}: no frames to write") from None
    points = frame.points
    n = len(points)
    block = np.asarray(frame.point_data.get("block", np.ones(n)), dtype=np.int64).reshape(n)
    used = sorted(set(block.tolist()))
    first_node = {b: int(np.argmax(block == b)) for b in used}
    corners = (max(used) + 1, max(used) + 2)                  # tags of the bounding-box corner entities
    real = _real(precision)
    count = 0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as stream:
        stream.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n")
        if block_names:
            stream.write(f"$PhysicalNames\n{len(used)}\n")
            for b in used:
                stream.write(f'0 {b} "{block_names.get(b, f"block_{b}")}"\n')
            stream.write("$EndPhysicalNames\n")
        # A block's entity sits at its first node; the corner entities carry no node and no group.
        stream.write(f"$Entities\n{len(used) + 2} 0 0 0\n")
        point_row = f"%d {real} {real} {real}"
        for b in used:
            stream.write(point_row % (b, *points[first_node[b]].tolist()) + f" 1 {b}\n")
        for tag, corner in zip(corners, (points.min(axis=0), points.max(axis=0))):
            stream.write(point_row % (tag, *corner.tolist()) + " 0\n")
        stream.write("$EndEntities\n")
        # Nodes and elements in tag order, one entity block per run of nodes of the same block,
        # so that readers that number points in file order (meshio) keep the frames' order.
        runs = _runs(block)
        stream.write(f"$Nodes\n{len(runs)} {n} 1 {n}\n")
        for b, first, last in runs:
            stream.write(f"0 {b} 0 {last - first}\n")
            np.savetxt(stream, np.arange(first + 1, last + 1), fmt="%d")
            _write_rows(stream, None, points[first:last], precision)
        stream.write(f"$EndNodes\n$Elements\n{len(runs)} {n} 1 {n}\n")
        for b, first, last in runs:
            ids = np.arange(first + 1, last + 1)
            stream.write(f"0 {b} {POINT_ELEMENT} {len(ids)}\n")
            np.savetxt(stream, np.column_stack([ids, ids]), fmt="%d")
        stream.write("$EndElements\n")
        while True:
            if len(frame.points) != n:
                raise PostprocessError(f"{frame.path}: {len(frame.points)} points, the first frame has {n}")
            for name, values in gmsh_views(frame.point_data, n):
                _node_data(stream, name, time, index, values, precision)
            count += 1
            try:
                index, time, frame = next(frames)
            except StopIteration:
                break
    return count


def write_damage_pos(path: str, frame: Frame, *, time: float, title: str, precision: int | None = None):
    """damage_final.pos: view "damage" of SP points; view "broken bonds" of SL lines if any broke."""
    points, damage = frame.points, frame.damage
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as stream:
        stream.write(f"// {title}: damage at t = {time:.6g} s, one scalar point per node (Gmsh parsed format)\n")
        stream.write('View "damage" {\n')
        real = _real(precision)
        row = f"SP({real},{real},{real}){{{real}}};\n"
        values = np.column_stack([points, damage])
        for start in range(0, len(values), CHUNK):
            block = values[start:start + CHUNK]
            stream.write((row * len(block)) % tuple(block.ravel().tolist()))
        stream.write(f"TIME{{{float(time)!r}}};\n}};\n")
        # Options of the view just read (the last one: the file may be merged beside other views):
        # damage is 0…1 whatever this frame's range is.
        last = "View[PostProcessing.NbViews-1]"
        stream.write(f"{last}.RangeType = 2; {last}.CustomMin = 0; {last}.CustomMax = 1;\n")
        bonds = frame.broken_bonds
        if len(bonds):
            stream.write('View "broken bonds" {\n')
            line = "SL(" + ",".join([real] * 6) + "){1,1};\n"
            ends = np.column_stack([points[bonds[:, 0]], points[bonds[:, 1]]])
            for start in range(0, len(ends), CHUNK):
                block = ends[start:start + CHUNK]
                stream.write((line * len(block)) % tuple(block.ravel().tolist()))
            stream.write("};\n")
            # Every bond carries the constant 1: no legend (it read "1 1 1"), one thin light grey.
            stream.write(f"{last}.ShowScale = 0; {last}.LineWidth = 1; "
                         f"{last}.ColorTable = {{{{160,160,160}}}};\n")


def read_msh_node_data(path: str) -> dict[str, list[tuple[float, int, np.ndarray, np.ndarray]]]:
    """Our reader of the $NodeData blocks of an ASCII MSH 2.2 file (meshio keeps only one block per
    name): {view name: [(time, time-step index, node tags (n,), values (n, components)), …]}."""
    views: dict[str, list] = {}
    with open(path, encoding="utf-8") as stream:
        lines: Iterator[str] = iter(stream)
        for line in lines:
            if line.strip() != "$NodeData":
                continue
            strings = [next(lines).strip().strip('"') for _ in range(int(next(lines)))]
            reals = [float(next(lines)) for _ in range(int(next(lines)))]
            integers = [int(next(lines)) for _ in range(int(next(lines)))]
            step, components, count = integers[0], integers[1], integers[2]
            rows = np.array(" ".join(next(lines) for _ in range(count)).split(), dtype=np.float64)
            rows = rows.reshape(count, components + 1)
            if next(lines).strip() != "$EndNodeData":
                raise PostprocessError(f"{path}: $NodeData '{strings[0]}' does not end with $EndNodeData")
            views.setdefault(strings[0], []).append(
                (reals[0] if reals else 0.0, step, rows[:, 0].astype(np.int64), rows[:, 1:]))
    return views
