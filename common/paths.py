"""Where the programs of the toolchain are: the repository, pdsolve and the Python interpreter.

Every Python user of the solver (peridyn, validation, bench, the tests) asks here, so that PDSOLVE
means the same everywhere: a solver built elsewhere (a sanitizer build, another worktree's) replaces
build/solver/pdsolve of this checkout, which is what `make solver` builds.
"""
from __future__ import annotations

import os

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILT_PDSOLVE = os.path.join(REPOSITORY, "build", "solver", "pdsolve")

# The stages run under Debian's interpreter: numpy, scipy, meshio and gmsh are its python3-*
# packages (pipeline/install-deps.sh), which another python3 first on PATH may lack.
PYTHON = "/usr/bin/python3"


def given_pdsolve() -> str | None:
    """The solver named by the PDSOLVE environment variable, or None when it names none."""
    return os.environ.get("PDSOLVE") or None


def pdsolve() -> str:
    """The pdsolve to run: $PDSOLVE if set, else build/solver/pdsolve of this checkout. Read at each
    call, so that a PDSOLVE set after import (a test's, a script's) counts."""
    return os.environ.get("PDSOLVE", BUILT_PDSOLVE)
