"""Gmsh views of the results, written by our own code:

- results.msh: MSH 2.2 ASCII. $Nodes (reference positions), $Elements with one 1-node point element
  (type 15) per node so that Gmsh draws point data, and one $NodeData block per frame for every
  point array the frame has (displacement, velocity, damage, block, … in the frame's order: a
  scalar view for 1 component, a vector view for 3, a tensor view for 9, a 2-component array padded
  with a zero z, any other count one scalar view `name[k]` per component), tagged with the frame's
  time and index, so that Gmsh animates them (Gmsh merges blocks of the same name into the time
  steps of one view). Tools → Options → View → "Displacement" display of `displacement` warps the body.
- damage_final.pos: Gmsh's parsed format, one scalar point SP(x,y,z){φ} per node (and one line
  SL per broken bond in a second view): Gmsh prints these as vector (PDF/SVG/EPS) images.
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


def _write_rows(stream, first_columns: np.ndarray, values: np.ndarray, precision: int | None):
    """Rows 'tag v1 v2 …' with integers in the first column and reals after it."""
    k = values.shape[1]
    row = "%d" + (" " + _real(precision)) * k + "\n"
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


def write_results_msh(path: str, frames: Iterable[tuple[int, float, Frame]], *,
                      block_names: dict | None = None, precision: int | None = None) -> int:
    """Write results.msh from (frame index, time, frame) triples, streaming one frame at a time.

    The nodes are the first frame's points; every frame must have as many. Element tags:
    physical = elementary = the node's block (PointData `block`, 1 if absent), named after
    `block_names` {id: name} in $PhysicalNames when given. Returns the number of frames written.
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
    count = 0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as stream:
        stream.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
        used = sorted(set(block.tolist()))
        if block_names:
            stream.write(f"$PhysicalNames\n{len(used)}\n")
            for b in used:
                stream.write(f'0 {b} "{block_names.get(b, f"block_{b}")}"\n')
            stream.write("$EndPhysicalNames\n")
        stream.write(f"$Nodes\n{n}\n")
        _write_rows(stream, np.arange(1, n + 1), points, precision)
        stream.write(f"$EndNodes\n$Elements\n{n}\n")
        ids = np.arange(1, n + 1)
        elements = np.column_stack([ids, np.full(n, POINT_ELEMENT), np.full(n, 2), block, block, ids])
        np.savetxt(stream, elements, fmt="%d")
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
        bonds = frame.broken_bonds
        if len(bonds):
            stream.write('View "broken bonds" {\n')
            line = "SL(" + ",".join([real] * 6) + "){1,1};\n"
            ends = np.column_stack([points[bonds[:, 0]], points[bonds[:, 1]]])
            for start in range(0, len(ends), CHUNK):
                block = ends[start:start + CHUNK]
                stream.write((line * len(block)) % tuple(block.ravel().tolist()))
            stream.write("};\n")


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
