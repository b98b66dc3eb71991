"""Run the gmsh command line on a .geo file, non-interactively, writing a msh4 file atomically."""
from __future__ import annotations

import os
import shutil
import subprocess

from pipeline.atomic import atomic_path

from .errors import PreprocessError

GMSH = "gmsh"
MAX_ERROR_LINES = 20


def mesh_geo(geo_path: str, out_msh_path: str, dimension: int, parameters: dict[str, float]) -> None:
    """`gmsh -<dimension> geo -o out -format msh4 -setnumber NAME VALUE ...`, written to a temporary
    name in the output directory and renamed on success. Gmsh's own error lines are in the
    PreprocessError raised when gmsh fails (non-zero exit or any 'Error' line)."""
    if dimension not in (1, 2, 3):
        raise PreprocessError(f"{geo_path}: mesh dimension must be 1, 2 or 3, not {dimension}")
    if not os.path.isfile(geo_path):
        raise PreprocessError(f"{geo_path}: no such .geo file")
    exe = shutil.which(GMSH)
    if exe is None:
        raise PreprocessError(f"{geo_path}: the gmsh command is not installed (Debian package gmsh)")
    with atomic_path(out_msh_path) as tmp:
        cmd = [exe, f"-{dimension}", geo_path, "-o", tmp, "-format", "msh4", "-nopopup"]
        for name, value in parameters.items():
            cmd += ["-setnumber", str(name), repr(float(value))]
        result = subprocess.run(cmd, stdin=subprocess.DEVNULL, capture_output=True, text=True)
        output = (result.stdout + "\n" + result.stderr).splitlines()
        errors = []
        for line in output:
            if line.startswith("Error") and line not in errors:
                errors.append(line)
        if result.returncode != 0 or errors:
            shown = errors[:MAX_ERROR_LINES] or output[-MAX_ERROR_LINES:]
            more = f"\n  ... ({len(errors) - MAX_ERROR_LINES} more)" if len(errors) > MAX_ERROR_LINES else ""
            raise PreprocessError(f"{geo_path}: gmsh failed (exit code {result.returncode}):\n  "
                                  + "\n  ".join(shown) + more)
        if os.path.getsize(tmp) == 0:
            raise PreprocessError(f"{geo_path}: gmsh wrote an empty mesh")
