"""The one atomic-file writer of the Python side: write under a temporary name in the target's
directory, then rename into place, so that an interrupted stage never leaves a half-written file.

The file gets the mode a plain open() would give it (0666 less the umask), not mkstemp's 0600.
"""
from __future__ import annotations

import contextlib
import os
import tempfile


def _umask() -> int:
    mask = os.umask(0)  # the only way to read it; set straight back
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str):
    """Yield a temporary path next to `path`; on success rename it to `path`, on error delete it.

    The temporary name ends with the final name (…-energy.png, …-mesh.msh) so that writers that
    look at the extension (matplotlib, gmsh) see the right one.
    """
    directory = os.path.dirname(os.path.abspath(path))
    os.makedirs(directory, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=".tmp-", suffix="-" + os.path.basename(path))
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual permissions
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_atomically(path: str, data: str | bytes):
    """Write text (UTF-8) or bytes to `path` atomically."""
    binary = isinstance(data, bytes)
    with atomic_path(path) as tmp, open(tmp, "wb" if binary else "w",
                                        **({} if binary else {"encoding": "utf-8", "newline": ""})) as stream:
        stream.write(data)
