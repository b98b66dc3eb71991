"""Gmsh views of the results, written by our own code:

- results.msh: MSH 4.1 *binary* (8-byte size_t, little-endian). Values are float64 whatever their
  digits, so it is smaller than the shortest-repr ASCII by less than one would think (membrane's 4
  frames of 2,500 nodes: 1.22 MB ASCII, 0.92 MB binary), but written 15 times faster (0.46 s against
  0.03 s, 7 Dec 2026) and read by Gmsh without parsing text. $Entities: one point entity per block (physical group = the block, named after
  it) that holds the block's nodes and their 1-node point elements (type 15, so that Gmsh draws
  point data), and two empty point entities at the lower and upper corners of the cloud's bounding
  box. Gmsh frames a view on the model's bounding box, the union of its entities' boxes, and a point
  entity's box is its one point: without the corners a one-block cloud opened zoomed on a dot
  (issue 16). Then one $NodeData block per frame for every point array the frame has
  (displacement, velocity, damage, block, … in the frame's order: a scalar view for 1 component, a
  vector view for 3, a tensor view for 9, a 2-component array padded with a zero z, any other count
  one scalar view `name[k]` per component), tagged with the frame's time and its time step 0…n-1 in
  the file, so that Gmsh animates them with one step per frame written (Gmsh merges blocks of the
  same name into the time steps of one view, and makes a step for every index up to the largest:
  tagged with the frames' indices 0, 15, 30, 43 it made 44 steps of which 40 were empty).
- results.msh.opt: Gmsh merges <file>.opt when it opens <file>. It hides the geometry's points, so
  that the entities above (the corners, a dot per block) do not show as stray dots in the view.
- damage_final.pos: Gmsh's parsed format, one scalar point SP(x,y,z){φ} per node, its colour range
  fixed to 0…1, and, if bonds broke, one line SL per broken bond in a second view drawn thin and
  grey without a legend (its values are a constant 1, whose legend read "1 1 1"). Gmsh prints these
  as vector (PDF/SVG/EPS) images.
Both are written under a temporary name and renamed into place.
"""
from __future__ import annotations

from typing import Iterable, Iterator

import numpy as np

from common.atomic import atomic_path
from .errors import PostprocessError
from .series import Frame

POINT_ELEMENT = 15  # Gmsh's 1-node point
CHUNK = 50000       # rows formatted per call, to bound memory on large clouds
SIZE_T = np.dtype("<u8")  # "4.1 1 8": size_t is 8 bytes
# Options Gmsh merges beside results.msh (results.msh.opt): no dots for the geometry's points.
OPTIONS = "// Merged by Gmsh when it opens results.msh (postprocess/gmsh_export.py)\nGeometry.Points = 0;\n"


def _real(precision: int | None) -> str:
    """%r writes Python's shortest representation that reads back to the same float64."""
    return "%r" if precision is None else f"%.{precision}g"


def _node_data(stream, name: str, time: float, step: int, values: np.ndarray):
    """One $NodeData block: ASCII tags (name, time, step, components, count), then binary rows
    (int32 node tag, float64 values) for nodes 1…n."""
    n, k = values.shape
    stream.write(f'$NodeData\n1\n"{name}"\n1\n{float(time)!r}\n3\n{step}\n{k}\n{n}\n'.encode())
    rows = np.empty(n, dtype=[("tag", "<i4"), ("values", "<f8", (k,))])
    rows["tag"] = np.arange(1, n + 1)
    rows["values"] = values
    stream.write(rows.tobytes())
    stream.write(b"\n$EndNodeData\n")


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


def _entity_block_header(dim: int, tag: int, kind: int, count: int) -> bytes:
    """An entity block's header in $Nodes (kind: parametric 0) or $Elements (kind: element type)."""
    return np.array([dim, tag, kind], dtype="<i4").tobytes() + np.array([count], dtype=SIZE_T).tobytes()


def write_results_msh(path: str, frames: Iterable[tuple[int, float, Frame]], *,
                      block_names: dict | None = None) -> int:
    """Write results.msh (and results.msh.opt beside it) from (frame index, time, frame) triples,
    streaming one frame at a time; the frames become time steps 0, 1, 2, … in the order given.

    The nodes are the first frame's points (node tag = index + 1); every frame must have as many.
    Each node and its point element (element tag = node tag) lie on the point entity of its block
    (PointData `block`, 1 if absent), which is physical group `block`, named after `block_names`
    {id: name} in $PhysicalNames when given. Returns the number of frames written. The values are
    float64 in binary: they round-trip exactly.
    """
    frames = iter(frames)
    try:
        _, time, frame = next(frames)
    except StopIteration:
        raise PostprocessError(f"{path}: no frames to write") from None
    points = np.asarray(frame.points, dtype=np.float64)
    n = len(points)
    block = np.asarray(frame.point_data.get("block", np.ones(n)), dtype=np.int64).reshape(n)
    used = sorted(set(block.tolist()))
    first_node = {b: int(np.argmax(block == b)) for b in used}
    corners = (max(used) + 1, max(used) + 2)                  # tags of the bounding-box corner entities
    count = 0
    with atomic_path(path) as tmp, open(tmp, "wb") as stream:
        stream.write(b"$MeshFormat\n4.1 1 8\n" + np.array([1], dtype="<i4").tobytes() + b"\n$EndMeshFormat\n")
        if block_names:
            stream.write(f"$PhysicalNames\n{len(used)}\n".encode())
            for b in used:
                stream.write(f'0 {b} "{block_names.get(b, f"block_{b}")}"\n'.encode())
            stream.write(b"$EndPhysicalNames\n")
        # A block's entity sits at its first node, in physical group `block`; the corner entities
        # carry no node and no group. Binary point entity: int tag, 3 doubles, size_t count, int tags.
        stream.write(b"$Entities\n" + np.array([len(used) + 2, 0, 0, 0], dtype=SIZE_T).tobytes())
        for b in used:
            stream.write(np.array([b], "<i4").tobytes() + points[first_node[b]].astype("<f8").tobytes()
                         + np.array([1], SIZE_T).tobytes() + np.array([b], "<i4").tobytes())
        for tag, corner in zip(corners, (points.min(axis=0), points.max(axis=0))):
            stream.write(np.array([tag], "<i4").tobytes() + corner.astype("<f8").tobytes()
                         + np.array([0], SIZE_T).tobytes())
        stream.write(b"\n$EndEntities\n")
        # Nodes and elements in tag order, one entity block per run of nodes of the same block,
        # so that readers that number points in file order (meshio) keep the frames' order.
        runs = _runs(block)
        stream.write(b"$Nodes\n" + np.array([len(runs), n, 1, n], dtype=SIZE_T).tobytes())
        for b, first, last in runs:
            stream.write(_entity_block_header(0, b, 0, last - first))
            stream.write(np.arange(first + 1, last + 1, dtype=SIZE_T).tobytes())
            stream.write(points[first:last].astype("<f8").tobytes())
        stream.write(b"\n$EndNodes\n$Elements\n" + np.array([len(runs), n, 1, n], dtype=SIZE_T).tobytes())
        for b, first, last in runs:
            ids = np.arange(first + 1, last + 1, dtype=SIZE_T)
            stream.write(_entity_block_header(0, b, POINT_ELEMENT, len(ids)))
            stream.write(np.column_stack([ids, ids]).astype(SIZE_T).tobytes())
        stream.write(b"\n$EndElements\n")
        while True:
            if len(frame.points) != n:
                raise PostprocessError(f"{frame.path}: {len(frame.points)} points, the first frame has {n}")
            for name, values in gmsh_views(frame.point_data, n):
                _node_data(stream, name, time, count, values)
            count += 1
            try:
                _, time, frame = next(frames)
            except StopIteration:
                break
    with atomic_path(path + ".opt") as tmp, open(tmp, "w", encoding="utf-8") as stream:
        stream.write(OPTIONS)
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
    """Our reader of the $NodeData blocks of results.msh (binary MSH 4.1 as written above; meshio
    keeps only one block per name): {view name: [(time, time-step index, node tags (n,),
    values (n, components)), …]}."""
    views: dict[str, list] = {}
    with open(path, "rb") as stream:
        data = stream.read()
    at = 0
    while True:
        at = data.find(b"$NodeData\n", at)
        if at < 0:
            return views
        lines = data[at:at + 4096].split(b"\n")
        strings_count = int(lines[1])
        strings = [lines[2 + k].strip().strip(b'"').decode() for k in range(strings_count)]
        i = 2 + strings_count
        reals = [float(lines[i + 1 + k]) for k in range(int(lines[i]))]
        i += 1 + len(reals)
        integers = [int(lines[i + 1 + k]) for k in range(int(lines[i]))]
        i += 1 + len(integers)
        step, components, count = integers[0], integers[1], integers[2]
        header = sum(len(line) + 1 for line in lines[:i])
        rows = np.frombuffer(data, dtype=[("tag", "<i4"), ("values", "<f8", (components,))],
                             count=count, offset=at + header)
        at += header + rows.nbytes
        if not data.startswith(b"\n$EndNodeData", at):
            raise PostprocessError(f"{path}: $NodeData '{strings[0]}' does not end with $EndNodeData")
        views.setdefault(strings[0], []).append(
            (reals[0] if reals else 0.0, step, rows["tag"].astype(np.int64), rows["values"].reshape(count, components).copy()))
