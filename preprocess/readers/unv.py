"""I-DEAS universal files (.unv): nodes (2411), elements (2412), groups (2467, 2477); our own reader.

A dataset sits between two lines holding `-1` (in columns 1-6), the first line after the opening
`-1` holding the dataset number. Datasets other than those above are skipped. Coordinates may use
Fortran 'D' exponents (1.0000000000000000D+00). Element node lists follow the FE descriptor id;
beam-like elements (ids 11-32) carry an extra orientation record before their nodes. Groups list
entities as (type code, tag, leaf, component) quadruples, two per line: type 7 = node, 8 = element.
Quadratic elements are reordered from the UNV order (corner, mid-side, corner, ...) to meshio's
(corners first), so that geometry can use the corner nodes.
"""
from __future__ import annotations

import warnings

import numpy as np

from ..errors import PreprocessError, PreprocessWarning
from ..mesh import Group, Mesh, element_dimension

BEAM_IDS = {11, 21, 22, 23, 24, 31, 32}

# FE descriptor id -> (meshio type, number of nodes, permutation from UNV order to meshio order or None)
_P_LINE3 = [0, 2, 1]
_P_TRI6 = [0, 2, 4, 1, 3, 5]
_P_QUAD8 = [0, 2, 4, 6, 1, 3, 5, 7]
_P_TET10 = [0, 2, 4, 9, 1, 3, 5, 6, 7, 8]
_P_WEDGE15 = [0, 2, 4, 9, 11, 13, 1, 3, 5, 10, 12, 14, 6, 7, 8]
_P_HEX20 = [0, 2, 4, 6, 12, 14, 16, 18, 1, 3, 5, 7, 13, 15, 17, 19, 8, 9, 10, 11]

FE_TYPES: dict[int, tuple[str, int, list | None]] = {}
for _fe in (11, 21, 22, 31):
    FE_TYPES[_fe] = ("line", 2, None)
for _fe in (23, 24, 32):
    FE_TYPES[_fe] = ("line3", 3, _P_LINE3)
for _base in (40, 50, 60, 70, 80, 90):   # plane stress, plane strain, plate, membrane, axisymmetric, thin shell
    FE_TYPES[_base + 1] = ("triangle", 3, None)
    FE_TYPES[_base + 2] = ("triangle6", 6, _P_TRI6)
    FE_TYPES[_base + 4] = ("quad", 4, None)
    FE_TYPES[_base + 5] = ("quad8", 8, _P_QUAD8)
FE_TYPES.update({
    111: ("tetra", 4, None),
    118: ("tetra10", 10, _P_TET10),
    112: ("wedge", 6, None),
    113: ("wedge15", 15, _P_WEDGE15),
    115: ("hexahedron", 8, None),
    116: ("hexahedron20", 20, _P_HEX20),
})

NODE_ENTITY = 7
ELEMENT_ENTITY = 8


class _Lines:
    """Lines of the file with 1-based numbers, for error messages that name the line."""

    def __init__(self, path: str):
        self.path = path
        with open(path, encoding="latin-1") as stream:
            self.lines = stream.read().splitlines()
        self.pos = 0  # index of the next line

    def error(self, lineno: int, message: str) -> PreprocessError:
        return PreprocessError(f"{self.path}:{lineno}: {message}")

    def next(self, what: str, dataset: int) -> tuple[int, str]:
        if self.pos >= len(self.lines):
            raise self.error(len(self.lines), f"truncated file: end of file in dataset {dataset} "
                             f"while reading {what} (missing lines or the closing '-1')")
        line = self.lines[self.pos]
        self.pos += 1
        if _is_delimiter(line):
            raise self.error(self.pos, f"dataset {dataset} ends early: expected {what}, found '-1'")
        return self.pos, line


def _is_delimiter(line: str) -> bool:
    return line.strip() == "-1"


def _ints(lines: _Lines, lineno: int, line: str, count: int | None, what: str) -> list[int]:
    """Integers of an I10 record; split on blanks, else fixed 10-character fields (wide labels touch)."""
    fields = line.split()
    if count is not None and len(fields) != count:
        fixed = [line[i:i + 10] for i in range(0, len(line.rstrip()), 10)]
        if len(fixed) == count:
            fields = fixed
    try:
        values = [int(f) for f in fields]
    except ValueError:
        raise lines.error(lineno, f"bad record for {what}: expected integers, got '{line.strip()}'") from None
    if count is not None and len(values) != count:
        raise lines.error(lineno, f"bad record for {what}: expected {count} integers, got {len(values)}: "
                          f"'{line.strip()}'")
    # Labels and counts become int64 arrays; a larger value would raise OverflowError there (fuzzing).
    for v in values:
        if abs(v) >= 2 ** 62:
            raise lines.error(lineno, f"bad record for {what}: {v} is too large for a label or a count")
    return values


def _floats(lines: _Lines, lineno: int, line: str, count: int, what: str) -> list[float]:
    """Reals of a D25.16 record (Fortran 'D' exponent allowed); fixed 25-character fields if needed."""
    text = line.replace("D", "E").replace("d", "e")
    fields = text.split()
    if len(fields) != count:
        fields = [text[i:i + 25] for i in range(0, len(text.rstrip()), 25)]
    try:
        values = [float(f) for f in fields]
    except ValueError:
        raise lines.error(lineno, f"bad record for {what}: expected {count} reals, got '{line.strip()}'") from None
    if len(values) != count:
        raise lines.error(lineno, f"bad record for {what}: expected {count} reals, got {len(values)}")
    return values


def _read_nodes(lines: _Lines, labels: list, coords: list):
    while True:
        if lines.pos >= len(lines.lines):
            raise lines.error(len(lines.lines), "truncated file: dataset 2411 (nodes) has no closing '-1'")
        line = lines.lines[lines.pos]
        if _is_delimiter(line):
            lines.pos += 1
            return
        lineno, line = lines.next("a node record", 2411)
        label = _ints(lines, lineno, line, 4, "a node (label, coordinate systems, colour)")[0]
        lineno, line = lines.next(f"the coordinates of node {label}", 2411)
        labels.append(label)
        coords.append(_floats(lines, lineno, line, 3, f"the coordinates of node {label}"))


def _read_elements(lines: _Lines, elements: list):
    """elements: list of (label, meshio type, node labels in meshio order, line number)."""
    while True:
        if lines.pos >= len(lines.lines):
            raise lines.error(len(lines.lines), "truncated file: dataset 2412 (elements) has no closing '-1'")
        if _is_delimiter(lines.lines[lines.pos]):
            lines.pos += 1
            return
        lineno, line = lines.next("an element record", 2412)
        label, fe_id, _, _, _, nnodes = _ints(lines, lineno, line, 6, "an element (label, FE descriptor id, "
                                              "physical property, material property, colour, nodes)")
        if fe_id in BEAM_IDS:
            blineno, bline = lines.next(f"the beam record of element {label}", 2412)
            _ints(lines, blineno, bline, 3, f"the beam record of element {label}")
        nodes: list[int] = []
        while len(nodes) < nnodes:   # 8 labels a line
            nlineno, nline = lines.next(f"the nodes of element {label} ({nnodes} nodes)", 2412)
            nodes += _ints(lines, nlineno, nline, min(8, nnodes - len(nodes)),
                           f"the nodes of element {label} ({nnodes} declared on line {lineno})")
        if fe_id not in FE_TYPES:
            raise lines.error(lineno, f"element {label}: FE descriptor id {fe_id} is not supported; "
                              f"supported ids: {', '.join(str(k) for k in sorted(FE_TYPES))}")
        ctype, expected, perm = FE_TYPES[fe_id]
        if nnodes != expected:
            raise lines.error(lineno, f"element {label}: FE descriptor id {fe_id} ({ctype}) has {expected} "
                              f"nodes, the record says {nnodes}")
        if perm is not None:
            nodes = [nodes[k] for k in perm]
        elements.append((label, ctype, nodes, lineno))


def _read_groups(lines: _Lines, dataset: int, groups: list):
    """groups: list of (name, node labels, element labels, line number of the name)."""
    while True:
        if lines.pos >= len(lines.lines):
            raise lines.error(len(lines.lines), f"truncated file: dataset {dataset} (groups) has no closing '-1'")
        if _is_delimiter(lines.lines[lines.pos]):
            lines.pos += 1
            return
        lineno, line = lines.next("a group record", dataset)
        count = _ints(lines, lineno, line, 8, "a group (number, active sets, number of entities)")[7]
        name_lineno, name_line = lines.next("the group name", dataset)
        name = name_line.strip()
        entities: list[int] = []
        while len(entities) < 4 * count:
            elineno, eline = lines.next(f"the entities of group '{name}' ({count} declared)", dataset)
            values = _ints(lines, elineno, eline, None, f"the entities of group '{name}'")
            if len(values) not in (4, 8):
                raise lines.error(elineno, f"bad record for the entities of group '{name}': expected 4 or 8 "
                                  f"integers, got {len(values)}")
            entities += values
        if len(entities) != 4 * count:
            raise lines.error(name_lineno, f"group '{name}': {count} entities declared, "
                              f"{len(entities) // 4} listed")
        ent = np.asarray(entities, dtype=np.int64).reshape(-1, 4)
        groups.append((name, ent[ent[:, 0] == NODE_ENTITY, 1], ent[ent[:, 0] == ELEMENT_ENTITY, 1], name_lineno))


def read(path: str) -> Mesh:
    lines = _Lines(path)
    labels: list[int] = []
    coords: list[list[float]] = []
    elements: list = []
    raw_groups: list = []
    seen_nodes = False
    while lines.pos < len(lines.lines):
        line = lines.lines[lines.pos]
        lines.pos += 1
        if not line.strip():
            continue
        if not _is_delimiter(line):
            raise lines.error(lines.pos, f"expected '-1' opening a dataset, found '{line.strip()[:40]}'")
        if lines.pos >= len(lines.lines):
            raise lines.error(lines.pos, "truncated file: '-1' without a dataset number")
        lineno, head = lines.pos + 1, lines.lines[lines.pos]
        lines.pos += 1
        try:
            dataset = int(head.split()[0])
        except (ValueError, IndexError):
            raise lines.error(lineno, f"expected a dataset number, found '{head.strip()[:40]}'") from None
        if dataset == 2411:
            seen_nodes = True
            _read_nodes(lines, labels, coords)
        elif dataset == 2412:
            _read_elements(lines, elements)
        elif dataset in (2467, 2477):
            _read_groups(lines, dataset, raw_groups)
        else:  # skip an unknown dataset up to its closing -1
            while lines.pos < len(lines.lines) and not _is_delimiter(lines.lines[lines.pos]):
                lines.pos += 1
            if lines.pos >= len(lines.lines):
                raise lines.error(len(lines.lines), f"truncated file: dataset {dataset} (opened on line "
                                  f"{lineno}) has no closing '-1'")
            lines.pos += 1

    if not seen_nodes or not labels:
        raise PreprocessError(f"{path}: no nodes (dataset 2411) in this universal file")
    label_arr = np.asarray(labels, dtype=np.int64)
    if len(np.unique(label_arr)) != len(label_arr):
        dup = label_arr[np.nonzero(np.bincount(np.unique(label_arr, return_inverse=True)[1]) > 1)[0][0]]
        raise PreprocessError(f"{path}: node label {dup} is defined more than once")
    order = np.argsort(label_arr)
    sorted_labels = label_arr[order]

    def node_index(values: np.ndarray, what: str, lineno: int) -> np.ndarray:
        pos = np.searchsorted(sorted_labels, values)
        pos = np.minimum(pos, len(sorted_labels) - 1)
        bad = sorted_labels[pos] != values
        if np.any(bad):
            raise PreprocessError(f"{path}:{lineno}: {what} refers to node {values[bad][0]}, "
                                  f"which dataset 2411 does not define")
        return order[pos]

    cells: dict[str, list] = {}
    element_where: dict[int, tuple[str, int]] = {}
    for label, ctype, nodes, lineno in elements:
        if label in element_where:
            raise PreprocessError(f"{path}:{lineno}: element label {label} is defined more than once")
        conn = cells.setdefault(ctype, [])
        element_where[label] = (ctype, len(conn))
        conn.append(node_index(np.asarray(nodes, np.int64), f"element {label}", lineno))
    cells_arr = {t: np.asarray(c, dtype=np.int64) for t, c in cells.items()}

    groups: dict[str, Group] = {}
    for name, node_labels, elem_labels, lineno in raw_groups:
        if name in groups:
            raise PreprocessError(f"{path}:{lineno}: group '{name}' is defined more than once")
        gcells: dict[str, list[int]] = {}
        dangling = []
        for label in elem_labels.tolist():
            where = element_where.get(label)
            if where is None:
                dangling.append(label)
                continue
            gcells.setdefault(where[0], []).append(where[1])
        if dangling:
            # gmsh lists its point elements in groups but does not write them to dataset 2412
            warnings.warn(f"{path}:{lineno}: group '{name}' refers to {len(dangling)} element(s) that "
                          f"dataset 2412 does not define (e.g. {dangling[0]}); ignored"
                          + ("" if gcells or len(node_labels) else "; the group is empty and dropped"),
                          PreprocessWarning, stacklevel=2)
            if not gcells and not len(node_labels):
                continue
        dims = [element_dimension(t) for t in gcells]
        groups[name] = Group(
            name=name, dim=max(dims) if dims else 0,
            cells={t: np.unique(np.asarray(v, np.int64)) for t, v in gcells.items()},
            explicit_nodes=np.unique(node_index(node_labels, f"group '{name}'", lineno)),
        )
    return Mesh(path=path, points=np.asarray(coords, dtype=np.float64), cells=cells_arr, groups=groups)
