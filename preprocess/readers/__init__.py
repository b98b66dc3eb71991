"""Mesh readers, one module per format, chosen by file extension (meshio's registry pattern)."""
from __future__ import annotations

import os

from ..errors import PreprocessError
from ..mesh import Mesh
from . import msh, unv

# extension -> reader(path) -> Mesh
READERS = {
    ".msh": msh.read,
    ".unv": unv.read,
}


def read_mesh(path: str) -> Mesh:
    """Read a mesh file with the reader registered for its extension."""
    ext = os.path.splitext(path)[1].lower()
    reader = READERS.get(ext)
    if reader is None:
        raise PreprocessError(f"{path}: unknown mesh format '{ext or '(no extension)'}'; "
                              f"known extensions: {', '.join(sorted(READERS))}")
    if not os.path.isfile(path):
        raise PreprocessError(f"{path}: no such mesh file")
    return reader(path)
