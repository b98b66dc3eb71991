"""The preprocessing stage as one call: mesh file → NodeCloud (what the driver calls)."""
from __future__ import annotations

from .cloud import NodeCloud
from .discretize import discretize
from .errors import PreprocessError
from .ordering import space_filling_order
from .readers import read_mesh


def build_node_cloud(mesh_path: str, *, dimension: int, thickness: float | None, method: str,
                     dx: float | None, block_names: list[str], set_layers: dict[str, float],
                     lattice_origin=None) -> NodeCloud:
    """Read `mesh_path` (.msh or .unv) and discretize it.

    method: 'lattice' (cell-centred grid of spacing dx clipped to the mesh) or 'mesh-nodes'
    (the mesh's own nodes). thickness [m] is required in 2D and ignored in 3D. block_names:
    the ordered block (material) names, block id = position + 1; each names a physical group of
    the top dimension, except that when the mesh has exactly one top-dimension group or none and
    one block name is given, every node belongs to that block. set_layers: name → layer [m] for
    lower-dimension groups. lattice_origin: a point the lattice passes through (nodes at
    origin + k·dx, as LAMMPS's lattice); None: cell centres of the mesh's bounding box. Every named physical group becomes a node set. See
    preprocess.discretize for the full rules on blocks and sets. The nodes are numbered along a
    space-filling curve (preprocess.ordering) for the solver's memory locality.
    Raises PreprocessError, whose message starts with the mesh path.
    """
    mesh = read_mesh(mesh_path)
    try:
        cloud = discretize(mesh, dimension=dimension, thickness=thickness, method=method, dx=dx,
                           block_names=list(block_names), set_layers=dict(set_layers or {}),
                           lattice_origin=lattice_origin)
    except MemoryError as err:
        raise PreprocessError(f"{mesh_path}: out of memory while discretizing "
                              f"({method}, dx = {dx}); use a larger dx") from err
    return space_filling_order(cloud)
