"""Mesh readers, one module per format, chosen by file extension (meshio's registry pattern)."""
from __future__ import annotations

import os
import stat

from pipeline.regular_file import kind_of

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
    # Only a regular file is read: a FIFO would block the reader's open() (issue 36, item 11).
    try:
        mode = os.stat(path).st_mode
    except OSError as err:
        raise PreprocessError(f"{path}: cannot read the mesh file: {err.strerror}") from None
    if not stat.S_ISREG(mode):
        raise PreprocessError(f"{path}: {kind_of(mode)}, not a regular file; give the case's "
                              f"mesh file ({', '.join(sorted(READERS))})")
    return reader(path)
