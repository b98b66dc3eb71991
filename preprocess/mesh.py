"""The internal mesh that every reader returns: points, elements by type, named physical groups."""
from __future__ import annotations

import dataclasses

import numpy as np

# Element types use meshio's names. For each: (dimension, number of corner nodes). Higher-order
# elements list their corner nodes first (gmsh/meshio/VTK order), so geometry uses conn[:, :corners].
ELEMENT_TYPES: dict[str, tuple[int, int]] = {
    "vertex": (0, 1),
    "line": (1, 2), "line3": (1, 2),
    "triangle": (2, 3), "triangle6": (2, 3),
    "quad": (2, 4), "quad8": (2, 4), "quad9": (2, 4),
    "tetra": (3, 4), "tetra10": (3, 4),
    "hexahedron": (3, 8), "hexahedron20": (3, 8), "hexahedron27": (3, 8),
    "wedge": (3, 6), "wedge15": (3, 6),
    "pyramid": (3, 5), "pyramid13": (3, 5),
}


def element_dimension(cell_type: str) -> int:
    return ELEMENT_TYPES[cell_type][0]


@dataclasses.dataclass
class Group:
    """A named physical group: elements (indices into Mesh.cells[type]) and/or explicit nodes."""
    name: str
    dim: int                                   # 0 points, 1 curves, 2 surfaces, 3 volumes
    cells: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)   # type -> element indices
    explicit_nodes: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0, np.int64))


@dataclasses.dataclass
class Mesh:
    """points (n, 3) float64; cells: type -> (m, k) int64 0-based connectivity; groups by name."""
    path: str
    points: np.ndarray
    cells: dict[str, np.ndarray]
    groups: dict[str, Group]

    def top_dimension(self) -> int:
        """Highest dimension of any element (-1 for a mesh without elements)."""
        dims = [element_dimension(t) for t, c in self.cells.items() if len(c)]
        return max(dims) if dims else -1

    def group_connectivity(self, name: str) -> dict[str, np.ndarray]:
        """The group's elements: type -> (m, k) connectivity."""
        group = self.groups[name]
        return {t: self.cells[t][idx] for t, idx in group.cells.items() if len(idx)}

    def group_nodes(self, name: str) -> np.ndarray:
        """Sorted node indices of the group: nodes of its elements plus its explicit nodes."""
        group = self.groups[name]
        parts = [self.cells[t][idx].ravel() for t, idx in group.cells.items()]
        parts.append(np.asarray(group.explicit_nodes, dtype=np.int64))
        return np.unique(np.concatenate(parts)) if parts else np.zeros(0, np.int64)

    def summary(self) -> str:
        cells = ", ".join(f"{len(c)} {t}" for t, c in self.cells.items())
        groups = ", ".join(f"{g.name} ({g.dim}D)" for g in self.groups.values()) or "none"
        return f"{len(self.points)} nodes; elements: {cells or 'none'}; physical groups: {groups}"
