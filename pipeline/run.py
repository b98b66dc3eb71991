"""The command line that the Makefile calls for each Python-side stage of a case.

    /usr/bin/python3 -m pipeline.run check CASE.yaml [MESH]              # MESH: names against its groups
    /usr/bin/python3 -m pipeline.run mesh-parameters CASE.yaml OUT.json   # rewritten only on change
    /usr/bin/python3 -m pipeline.run mesh CASE.yaml GEO OUT.msh
    /usr/bin/python3 -m pipeline.run preprocess CASE.yaml MESH OUT_DIR    # nodes.vtu + case.json

Every check runs before any file is written; files are written under a temporary name and renamed,
so an interrupted stage leaves nothing half-written. The stages themselves are the functions of
pipeline/stages.py; this wrapper adds what a command line owes its caller: no input may lead out of
the case folder, the output folder is locked, and each error is one line with its exit code.
"""
from __future__ import annotations

import argparse
import contextlib
import os
import sys
import warnings

from common.atomic import DISK_FULL_EXIT, WriteError
from common.output_lock import FolderInUse, output_lock

from . import stages
from .case import CaseError
from .inputs import check_case_inputs
from .solver_physics import SolverError


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="pipeline.run", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("check", help="validate a case file (and its names against MESH, if given)")
    p.add_argument("case")
    p.add_argument("mesh", nargs="?", help="the case's mesh, when it exists: its physical groups")
    p.set_defaults(stage=lambda args: stages.check(args.case, args.mesh))
    p = sub.add_parser("mesh-parameters", help="write the gmsh parameters of a case if they changed")
    p.add_argument("case")
    p.add_argument("out")
    p.set_defaults(stage=lambda args: stages.mesh_parameters(args.case, args.out))
    p = sub.add_parser("mesh", help="mesh the case's .geo with gmsh")
    p.add_argument("case")
    p.add_argument("geo")
    p.add_argument("out")
    p.set_defaults(stage=lambda args: stages.mesh(args.case, args.geo, args.out))
    p = sub.add_parser("preprocess", help="mesh → node cloud (nodes.vtu) and resolved case.json")
    p.add_argument("case")
    p.add_argument("mesh")
    p.add_argument("out_dir")
    p.set_defaults(stage=lambda args: stages.preprocess(args.case, args.mesh, args.out_dir))
    return parser


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    # Preprocess warnings name their file already; print them as such, not as Python source lines.
    warnings.showwarning = lambda message, *rest, **kw: print(f"warning: {message}", file=sys.stderr)
    try:
        # Before a stage reads anything: no input may lead out of the case folder (issue 36).
        check_case_inputs(args.case, getattr(args, "geo", None), getattr(args, "mesh", None))
        # A stage that writes takes its output folder's lock, or finds make's (PD_LOCK_FD): run by
        # hand beside a make of the same case it wrote into that run's files (issue 36 probe).
        folder = args.out_dir if args.command == "preprocess" else (
            os.path.dirname(os.path.abspath(args.out)) if args.command in ("mesh", "mesh-parameters") else None)
        with output_lock(folder, f"python3 -m pipeline.run {args.command}") if folder else contextlib.nullcontext():
            args.stage(args)
    except FolderInUse as err:
        print(err, file=sys.stderr)
        return 75
    except CaseError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except WriteError as err:  # a full disk: its own exit code, as in the solver
        print(f"error: {err}", file=sys.stderr)
        return DISK_FULL_EXIT
    except SolverError as err:  # pdsolve missing or refusing: preprocess asks it for the stable step
        print(f"error: {err}", file=sys.stderr)
        return 2
    except Exception as err:  # preprocess errors carry the file name in their message
        if type(err).__name__ == "PreprocessError":
            print(f"error: {err}", file=sys.stderr)
            return 2
        raise
    return 0


if __name__ == "__main__":
    sys.exit(main())
