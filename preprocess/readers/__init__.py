"""Mesh readers, one module per format, chosen by file extension (meshio's registry pattern)."""
from __future__ import annotations

import os
import stat

from common.regular_file import kind_of

from ..errors import PreprocessError
from ..mesh import Mesh
from . import msh, unv

# A given mesh is read whole into memory: measured peaks of 3.5x the file size for a .msh (29.5 MB
# msh4, 290,147 nodes: 164 MB) and 7.4x for a .unv (87 MB: 704 MB, 18 s), so a file is refused when
# 8x its size is more than half of the memory available, and above MAX_MESH_BYTES unless FORCE=1:
# 1 GiB of .msh is some 10 million nodes (97 bytes a node), beyond the cases this pipeline runs.
# A 3 GB .msh was read for 61 s before failing with an empty reason.
MAX_MESH_BYTES = 1 << 30
READ_MEMORY_FACTOR = 8

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
    check_mesh_size(path)
    try:
        return reader(path)
    except MemoryError:
        raise PreprocessError(f"{path}: ran out of memory while reading the mesh; use a coarser mesh or a machine "
                              "with more memory") from None


def check_mesh_size(path: str):
    """PreprocessError, before reading, for a mesh file too large to read (see MAX_MESH_BYTES)."""
    from common.memory import available_memory

    size = os.path.getsize(path)
    half = 0.5 * available_memory()
    if READ_MEMORY_FACTOR * size > half:
        raise PreprocessError(f"{path}: {size / 1e6:.0f} MB; reading it takes up to {READ_MEMORY_FACTOR}x that, more "
                              f"than half of the {2 * half / 1e6:.0f} MB of memory available: use a coarser mesh or a "
                              "machine with more memory")
    if size > MAX_MESH_BYTES and os.environ.get("FORCE") != "1":
        raise PreprocessError(f"{path}: {size / 1e6:.0f} MB, more than the {MAX_MESH_BYTES / 1e6:.0f} MB a mesh file may "
                              "have (about 10 million nodes); use a coarser mesh, or read it anyway with FORCE=1 "
                              "(make FORCE=1 case=...)")
