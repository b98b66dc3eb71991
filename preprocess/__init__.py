"""Preprocessor: gmsh meshing, mesh readers (.msh via meshio, our own .unv reader),
discretization into a node cloud, and the node file of pipeline/formats.md §2."""
from .build import build_node_cloud
from .cloud import NodeCloud
from .errors import PreprocessError, PreprocessWarning
from .mesh import Group, Mesh
from .readers import READERS, read_mesh

__all__ = ["build_node_cloud", "NodeCloud", "PreprocessError", "PreprocessWarning", "Group", "Mesh",
           "READERS", "read_mesh"]
