"""The driver that the Makefile calls for each Python-side stage of a case.

    /usr/bin/python3 -m pipeline.run check CASE.yaml [MESH]              # MESH: names against its groups
    /usr/bin/python3 -m pipeline.run mesh-parameters CASE.yaml OUT.json   # rewritten only on change
    /usr/bin/python3 -m pipeline.run mesh CASE.yaml GEO OUT.msh
    /usr/bin/python3 -m pipeline.run preprocess CASE.yaml MESH OUT_DIR    # nodes.vtu + case.json

Every check runs before any file is written; files are written under a temporary
name and renamed, so an interrupted stage leaves nothing half-written.
"""
from __future__ import annotations

import argparse
import contextlib
import difflib
import json
import math
import os
import sys
import warnings

from .body import check_body, check_lengths, check_mesh_cost, check_mesh_growth, probe_geometry
from .atomic import DISK_FULL_EXIT, WriteError, write_atomically
from .case import CaseError, load_case
from .conditions import check_condition_overlaps
from .cost import check_cost
from .inputs import check_case_inputs
from .output_lock import FolderInUse, output_lock
from .regular_file import open_regular
from .resolve import check_set_names, resolve
from .solver_physics import CaseQuery, SolverError
from .stability import BOND_SLACK, check_discretized_case


def cmd_check(args):
    """The case file alone; with MESH (make passes it whenever the mesh exists), also its material
    and node-set names against the mesh's physical groups, as preprocess would check them."""
    case = load_case(args.case)
    checked = ""
    geo = case_geo(args.case)
    if geo is not None:
        from preprocess.geo_guard import check_geo

        check_geo(geo)
        check_geometry(case, geo)
        checked = f"; the body of {os.path.basename(geo)} is sound"
    if args.mesh:
        from preprocess import read_mesh
        from preprocess.discretize import missing_blocks

        mesh = read_mesh(args.mesh)
        top = [g.name for g in mesh.groups.values() if g.dim == case["dimension"]]
        missing = missing_blocks(mesh, case["dimension"], list(case["materials"]))
        problems = []
        if missing:
            err = CaseError("")
            err.missing_blocks, err.top_groups = missing, top
            problems.append(str(missing_block_error(case, args.mesh, err)))
        try:
            check_set_names(case, list(mesh.groups))
        except CaseError as error:
            problems.append(str(error))
        if problems:
            raise CaseError("\n".join(problems))
        checked += f"; materials and node sets match the physical groups of {args.mesh}"
    print(f"{args.case}: ok ({case['dimension']}D {case['analysis']}, "
          f"{len(case['materials'])} block(s), end time {case['time']['end']:g} s{checked})")


def cmd_mesh_parameters(args):
    """Keep the gmsh parameters in their own file so that Make re-meshes only when they change."""
    case = load_case(args.case)
    text = json.dumps(case["geometry"]["parameters"], sort_keys=True, indent=1) + "\n"
    try:
        # open_regular: a FIFO in its place would block a plain open(); it is replaced like any
        # stale file (NotRegularFile is an OSError)
        with open_regular(args.out) as stream:
            if stream.read(len(text.encode("utf-8")) + 1).decode("utf-8", "replace") == text:
                return
    except OSError:
        pass
    write_atomically(args.out, text)


def cmd_mesh(args):
    from preprocess.gmsh_mesh import mesh_geo

    case = load_case(args.case)
    probe = check_geometry(case, args.geo)
    # Before gmsh meshes: its size and the lattice's (issue 17, item 11); FORCE=1 runs it anyway.
    plan = check_mesh_cost(case, args.geo, probe, os.path.dirname(os.path.abspath(args.out)))
    check_mesh_growth(case, args.geo, probe, os.path.dirname(os.path.abspath(args.out)))
    if plan:
        print(f"{args.case}: {plan}")
    try:
        mesh_geo(args.geo, args.out, case["dimension"], case["geometry"]["parameters"])
    except Exception as err:
        # A body the checks before meshing let through (a hole inside the outer loop's box but
        # outside a non-convex outline) still fails here: named at the parameters' line too.
        if type(err).__name__ != "PreprocessError" or "gmsh failed" not in str(err) or not case["geometry"]["parameters"]:
            raise
        lines = case["_lines"]
        line = lines.get(("geometry", "parameters"), lines.get(("geometry",), 1))
        given = ", ".join(f"{k} = {v:g}" for k, v in case["geometry"]["parameters"].items())
        raise CaseError(f"{case['_path']}:{line}: geometry.parameters: gmsh could not mesh the body with {given}; "
                        f"check that they describe a sound body:\n{err}") from err


def check_geometry(case: dict, geo: str) -> dict:
    """The gmsh parameters and the body they make (pipeline/body.py), before any meshing."""
    check_parameters_used(case, geo)
    check_lengths(case, geo)
    probe = probe_geometry(case, geo)
    check_body(case, geo, probe)
    return probe


def case_geo(yaml_path: str) -> str | None:
    """cases/<case>/<case>.geo, when the case is meshed from it (no .unv or .msh of its own)."""
    folder = os.path.dirname(os.path.abspath(yaml_path))
    name = os.path.basename(folder)
    if any(os.path.exists(os.path.join(folder, name + ext)) for ext in (".unv", ".msh")):
        return None
    geo = os.path.join(folder, name + ".geo")
    return geo if os.path.isfile(geo) else None


def check_parameters_used(case: dict, geo: str):
    """A gmsh parameter that the .geo never names is ignored by gmsh: an error at its line."""
    from preprocess.geo_guard import geo_identifiers

    parameters = case["geometry"]["parameters"]
    if not parameters:
        return
    names = geo_identifiers(geo)
    lines = case["_lines"]
    errors = []
    for name in parameters:
        if name not in names:
            close = difflib.get_close_matches(name, sorted(names), n=1)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            line = lines.get(("geometry", "parameters", name), lines.get(("geometry",), 1))
            errors.append(f"{case['_path']}:{line}: geometry.parameters.{name}: {geo} never uses '{name}', so gmsh "
                          f"would ignore it{hint}; give only the names the .geo defines")
    if errors:
        raise CaseError("\n".join(errors))


def missing_block_error(case: dict, mesh: str, err) -> CaseError:
    """A material whose name is no top-dimension physical group of the mesh, reported at its line
    of the case file (the mesh is what it was looked up in)."""
    lines = case["_lines"]
    messages = []
    for name, reason in err.missing_blocks.items():
        line = lines.get(("materials", name), lines.get(("materials",), 1))
        close = difflib.get_close_matches(name, err.top_groups, n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        messages.append(f"{case['_path']}:{line}: materials.{name}: {reason} in {mesh}{hint}; a material "
                        f"names the physical group holding its nodes, and the mesh's "
                        f"{case['dimension']}D groups are: {', '.join(err.top_groups) or 'none'}")
    return CaseError("\n".join(messages))


def run_cost(case: dict, resolved: dict, cloud, query: CaseQuery | None = None) -> dict:
    """The estimate of pipeline/cost.py for this case: bonds counted on a sample, eq. 2.5's step
    (the solver's: query, made here if not given, see solver_physics.CaseQuery)."""
    import numpy as np
    from scipy.spatial import cKDTree

    from .cost import estimate, mean_bonds

    points = np.asarray(cloud.points)
    tree = cKDTree(points)
    time = case["time"]
    implicit = time["integrator"] == "implicit" or (time["integrator"] == "mixed" and
                                                     case["mixed"]["start"] == "implicit")
    # eq. 2.5's step: Verlet's with its safety factor, and the scale of an implicit step's accuracy
    dt_stable = (query or CaseQuery(resolved, cloud)).stable_step()[0] if isinstance(time["dt"], str) or implicit \
        else None
    if isinstance(time["dt"], str):
        dt = dt_stable * float(time["safety_factor"])   # "exact" is larger: this is an upper bound
    else:
        dt = float(time["dt"])
    bonds = mean_bonds(points, tree, float(resolved["horizon"]), BOND_SLACK) * len(points)
    return estimate(case, cloud, bonds, dt if dt > 0 and math.isfinite(dt) else float(time["end"]), dt_stable)


def cmd_preprocess(args):
    from preprocess import PreprocessError, build_node_cloud
    from preprocess.node_file import write_node_file

    case = load_case(args.case)
    disc = case["discretization"]
    try:
        cloud = build_node_cloud(
            args.mesh,
            dimension=case["dimension"],
            thickness=case["thickness"],
            method=disc["method"],
            dx=disc["dx"],
            block_names=list(case["materials"]),
            set_layers={name: opts["layer"] for name, opts in case["node_sets"].items()
                        if opts["layer"] is not None},
            lattice_origin=disc["origin"],
        )
    except PreprocessError as err:
        if not getattr(err, "missing_blocks", None):
            raise
        raise missing_block_error(case, args.mesh, err) from err
    resolved = resolve(case, node_sets=list(cloud.sets), grid_spacing=float(cloud.grid_spacing),
                       nodes_file="nodes.vtu")
    # Isolated nodes and the eq. 2.5 step (unit mistakes) are checked before anything is written: the
    # step is pdsolve's, asked on a temporary copy of the cloud and case.json (solver_physics.py).
    query = CaseQuery(resolved, cloud, named=os.path.join(args.out_dir, "case.json"),
                      solver=getattr(args, "solver", None))  # peridyn's solver; else PDSOLVE or build/'s
    for warning in check_condition_overlaps(case, cloud.sets) + check_discretized_case(case, resolved, cloud, query):
        print(f"warning: {warning}", file=sys.stderr)
    plan = check_cost(case, run_cost(case, resolved, cloud, query), args.out_dir)  # stops a huge run unless FORCE=1
    os.makedirs(args.out_dir, exist_ok=True)
    write_node_file(os.path.join(args.out_dir, "nodes.vtu"), cloud)
    write_atomically(os.path.join(args.out_dir, "case.json"), json.dumps(resolved, indent=1) + "\n")
    print(f"{args.case}: {len(cloud.volume)} nodes, dx = {cloud.grid_spacing:.6g} m, "
          f"horizon = {resolved['horizon']:.6g} m, node sets: {', '.join(resolved['node_sets'])}")
    print(f"{args.case}: {plan}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="pipeline.run", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("check", help="validate a case file (and its names against MESH, if given)")
    p.add_argument("case")
    p.add_argument("mesh", nargs="?", help="the case's mesh, when it exists: its physical groups")
    p.set_defaults(func=cmd_check)
    p = sub.add_parser("mesh-parameters", help="write the gmsh parameters of a case if they changed")
    p.add_argument("case")
    p.add_argument("out")
    p.set_defaults(func=cmd_mesh_parameters)
    p = sub.add_parser("mesh", help="mesh the case's .geo with gmsh")
    p.add_argument("case")
    p.add_argument("geo")
    p.add_argument("out")
    p.set_defaults(func=cmd_mesh)
    p = sub.add_parser("preprocess", help="mesh → node cloud (nodes.vtu) and resolved case.json")
    p.add_argument("case")
    p.add_argument("mesh")
    p.add_argument("out_dir")
    p.set_defaults(func=cmd_preprocess)
    args = parser.parse_args(argv)
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
            args.func(args)
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
