"""Run the gmsh command line on a .geo file, non-interactively, writing a msh4 file atomically."""
from __future__ import annotations

import os
import shutil
import subprocess
import tempfile

from common.atomic import WriteError, atomic_path, disk_full_message, free_megabytes

from . import sandbox
from .errors import PreprocessError
from .geo_guard import check_geo

GMSH = "gmsh"
MAX_ERROR_LINES = 20
# A mesh of the shipped cases takes seconds; a .geo that loops (For without end, a huge mesh)
# must not hold `make` for ever. PD_GMSH_TIMEOUT (seconds) changes the limit.
DEFAULT_TIMEOUT = 600.0


def gmsh_timeout() -> float:
    text = os.environ.get("PD_GMSH_TIMEOUT", "")
    if not text:
        return DEFAULT_TIMEOUT
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value > 0 or value != value or value == float("inf"):
        raise PreprocessError(f"PD_GMSH_TIMEOUT={text!r}: expected a number of seconds > 0")
    return value


def mesh_geo(geo_path: str, out_msh_path: str, dimension: int, parameters: dict[str, float],
             timeout: float | None = None) -> None:
    """`gmsh -<dimension> geo -o out -format msh4 -setnumber NAME VALUE ...`, written to a temporary
    name in the output directory and renamed on success. Gmsh's own error lines are in the
    PreprocessError raised when gmsh fails (non-zero exit or any 'Error' line).

    The .geo (and every file it makes gmsh read) is checked first by geo_guard: a .geo that runs
    commands or writes files is refused before gmsh starts; gmsh then runs in a sandbox
    (run_gmsh). gmsh is stopped after `timeout` seconds (default PD_GMSH_TIMEOUT, else
    DEFAULT_TIMEOUT) and capped in memory (sandbox.memory_cap)."""
    if dimension not in (1, 2, 3):
        raise PreprocessError(f"{geo_path}: mesh dimension must be 1, 2 or 3, not {dimension}")
    if not os.path.isfile(geo_path):
        raise PreprocessError(f"{geo_path}: no such .geo file")
    check_geo(geo_path)
    limit = gmsh_timeout() if timeout is None else timeout
    with atomic_path(out_msh_path) as tmp:
        result = run_gmsh(geo_path, dimension, parameters, tmp, limit)
        check_gmsh_result(geo_path, result)
        if os.path.getsize(tmp) == 0:
            raise PreprocessError(f"{geo_path}: gmsh wrote an empty mesh")
        check_complete_msh(tmp, out_msh_path)


def check_gmsh_result(geo_path: str, result: subprocess.CompletedProcess):
    """PreprocessError with gmsh's error lines when it failed (non-zero exit or any 'Error' line)."""
    output = (result.stdout + "\n" + result.stderr).splitlines()
    errors = []
    for line in output:
        if line.startswith("Error") and line not in errors:
            errors.append(line)
    # At the memory cap gmsh's allocation throws std::bad_alloc and it aborts (bwrap: exit 134).
    killed = result.returncode < 0 or result.returncode >= 128
    if killed or any("bad_alloc" in line or "Out of memory" in line for line in output):
        raise PreprocessError(f"{geo_path}: gmsh ran out of the memory it may use ({sandbox.memory_cap() / 1e6:.0f} "
                              "MB: half of the memory available, all of it with FORCE=1) or was killed (exit "
                              f"code {result.returncode}); coarsen the mesh (a larger mesh size)")
    if result.returncode != 0 or errors:
        shown = errors[:MAX_ERROR_LINES] or output[-MAX_ERROR_LINES:]
        more = f"\n  ... ({len(errors) - MAX_ERROR_LINES} more)" if len(errors) > MAX_ERROR_LINES else ""
        raise PreprocessError(f"{geo_path}: gmsh failed (exit code {result.returncode}):\n  "
                              + "\n  ".join(shown) + more)


def run_gmsh(geo_path: str, dimension: int, parameters: dict[str, float], out_path: str,
             timeout: float) -> subprocess.CompletedProcess:
    """`gmsh -<dimension> geo -o out -format msh4 -setnumber NAME VALUE ...` in the sandbox
    (preprocess/sandbox.py): the case folder read-only, and writable only a fresh folder next to
    `out_path`, from which the mesh is moved to `out_path` once gmsh has ended. A .geo that gets
    past geo_guard still cannot run a program or write elsewhere. TimeoutExpired and
    PreprocessError (gmsh stopped at the time limit, or the sandbox cannot start) are the caller's."""
    exe = shutil.which(GMSH)
    if exe is None:
        raise PreprocessError(f"{geo_path}: the gmsh command is not installed (Debian package gmsh)")
    geo = os.path.realpath(geo_path)
    workdir = tempfile.mkdtemp(prefix=".gmsh-", dir=os.path.dirname(os.path.abspath(out_path)))
    try:
        written = os.path.join(workdir, "mesh.msh")
        cmd = [exe, f"-{dimension}", geo, "-o", written, "-format", "msh4", "-nopopup"]
        for name, value in parameters.items():
            cmd += ["-setnumber", str(name), repr(float(value))]
        try:
            result = sandbox.run(cmd, geo_path, read_only=[os.path.dirname(geo)], writable=[workdir],
                                 cwd=os.path.dirname(geo), timeout=timeout)
        except subprocess.TimeoutExpired:  # subprocess.run has killed gmsh
            raise PreprocessError(f"{geo_path}: gmsh did not finish within {timeout:g} s and was stopped; "
                                  f"coarsen the mesh (a larger mesh size) or raise the limit with "
                                  f"PD_GMSH_TIMEOUT=<seconds>") from None
        if os.path.isfile(written) and not os.path.islink(written):
            os.replace(written, out_path)
        return result
    finally:
        shutil.rmtree(workdir, ignore_errors=True)


def check_complete_msh(tmp: str, out_msh_path: str):
    """gmsh exits 0 even when the disk fills while it writes (issue 17, item 6): a whole .msh
    starts with $MeshFormat and ends with the $End line of its last section; anything else is cut
    short and is not kept (the atomic writer removes it)."""
    with open(tmp, "rb") as stream:
        head = stream.read(11)
        stream.seek(max(0, os.path.getsize(tmp) - 256))
        tail = stream.read().rstrip(b"\r\n\0 ").rsplit(b"\n", 1)[-1]
    if head == b"$MeshFormat" and tail.startswith(b"$End"):
        return
    directory = os.path.dirname(os.path.abspath(out_msh_path))
    if free_megabytes(directory) < 1.0:
        raise WriteError(disk_full_message(out_msh_path))
    raise PreprocessError(f"{out_msh_path}: gmsh wrote an incomplete mesh (it ends with "
                          f"{tail[-40:].decode('ascii', 'replace')!r}, not an $End line); "
                          "the file was not kept: check the disk and run make again")
