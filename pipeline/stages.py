"""The stages of a case as plain functions, one per stage, with named arguments: check, mesh_parameters,
mesh, preprocess, solve and postprocess. The Makefile reaches them through pipeline/run.py's command
line; peridyn's Case.run, validation, the end-to-end tests and bench call them directly.

A stage checks everything before it writes, and writes each file under a temporary name that is
renamed into place (common/atomic.py), so an interrupted stage leaves nothing half-written. What a
stage does not do is its caller's: pipeline/run.py checks that no input leads out of the case folder
and takes the output folder's lock (common/output_lock.py); peridyn holds the lock of its run.
Errors are raised (CaseError, PreprocessError, WriteError, solver_physics.SolverError), never
turned into exit codes here.
"""
from __future__ import annotations

import difflib
import json
import math
import os
import subprocess
import sys

from common.atomic import write_atomically
from common.paths import pdsolve
from common.regular_file import open_regular

from .body import check_body, check_lengths, check_mesh_cost, check_mesh_growth, probe_geometry
from .case import CaseError, load_case
from .conditions import check_condition_overlaps
from .cost import check_cost
from .resolve import check_set_names, resolve
from .solver_physics import CaseQuery
from .stability import BOND_SLACK, check_discretized_case


def check(case_file: str, mesh: str | None = None) -> None:
    """The case file alone; with `mesh` (make passes it whenever the mesh exists), also its material
    and node-set names against the mesh's physical groups, as preprocess would check them."""
    case = load_case(case_file)
    checked = ""
    geo = case_geo(case_file)
    if geo is not None:
        from preprocess.geo_guard import check_geo

        check_geo(geo)
        check_geometry(case, geo)
        checked = f"; the body of {os.path.basename(geo)} is sound"
    if mesh:
        from preprocess import read_mesh
        from preprocess.discretize import missing_blocks

        mesh_read = read_mesh(mesh)
        top = [g.name for g in mesh_read.groups.values() if g.dim == case["dimension"]]
        missing = missing_blocks(mesh_read, case["dimension"], list(case["materials"]))
        problems = []
        if missing:
            err = CaseError("")
            err.missing_blocks, err.top_groups = missing, top
            problems.append(str(missing_block_error(case, mesh, err)))
        try:
            check_set_names(case, list(mesh_read.groups))
        except CaseError as error:
            problems.append(str(error))
        if problems:
            raise CaseError("\n".join(problems))
        checked += f"; materials and node sets match the physical groups of {mesh}"
    print(f"{case_file}: ok ({case['dimension']}D {case['analysis']}, "
          f"{len(case['materials'])} block(s), end time {case['time']['end']:g} s{checked})")


def mesh_parameters(case_file: str, out: str) -> None:
    """Keep the gmsh parameters in their own file, `out`, so that make re-meshes only when they change."""
    case = load_case(case_file)
    text = json.dumps(case["geometry"]["parameters"], sort_keys=True, indent=1) + "\n"
    try:
        # open_regular: a FIFO in its place would block a plain open(); it is replaced like any
        # stale file (NotRegularFile is an OSError)
        with open_regular(out) as stream:
            if stream.read(len(text.encode("utf-8")) + 1).decode("utf-8", "replace") == text:
                return
    except OSError:
        pass
    write_atomically(out, text)


def mesh(case_file: str, geo: str, out: str) -> None:
    """Mesh the case's .geo with gmsh into `out`, once the parameters, the body they make and the
    cost of meshing it have passed their checks."""
    from preprocess.gmsh_mesh import mesh_geo

    case = load_case(case_file)
    probe = check_geometry(case, geo)
    # Before gmsh meshes: its size and the lattice's (issue 17, item 11); FORCE=1 runs it anyway.
    plan = check_mesh_cost(case, geo, probe, os.path.dirname(os.path.abspath(out)))
    check_mesh_growth(case, geo, probe, os.path.dirname(os.path.abspath(out)))
    if plan:
        print(f"{case_file}: {plan}")
    try:
        mesh_geo(geo, out, case["dimension"], case["geometry"]["parameters"])
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


def preprocess(case_file: str, mesh: str, out_dir: str, *, solver: str | None = None) -> None:
    """The mesh to a node cloud: out_dir/nodes.vtu and the resolved out_dir/case.json the solver
    reads, once the discretized case and the run's cost have passed their checks. Those checks take
    eq. 2.5's step from the solver (pdsolve --physics, pipeline/solver_physics.py): `solver`, default
    $PDSOLVE, else build/solver/pdsolve (common/paths.py); SolverError when it is missing or refuses."""
    from preprocess import PreprocessError, build_node_cloud
    from preprocess.node_file import write_node_file

    case = load_case(case_file)
    disc = case["discretization"]
    try:
        cloud = build_node_cloud(
            mesh,
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
        raise missing_block_error(case, mesh, err) from err
    resolved = resolve(case, node_sets=list(cloud.sets), grid_spacing=float(cloud.grid_spacing),
                       nodes_file="nodes.vtu")
    # Isolated nodes and the eq. 2.5 step (unit mistakes) are checked before anything is written: the
    # step is pdsolve's, asked on a temporary copy of the cloud and case.json (solver_physics.py).
    query = CaseQuery(resolved, cloud, named=os.path.join(out_dir, "case.json"), solver=solver)
    for warning in check_condition_overlaps(case, cloud.sets) + check_discretized_case(case, resolved, cloud, query):
        print(f"warning: {warning}", file=sys.stderr)
    plan = check_cost(case, run_cost(case, resolved, cloud, query), out_dir)  # stops a huge run unless FORCE=1
    os.makedirs(out_dir, exist_ok=True)
    write_node_file(os.path.join(out_dir, "nodes.vtu"), cloud)
    write_atomically(os.path.join(out_dir, "case.json"), json.dumps(resolved, indent=1) + "\n")
    print(f"{case_file}: {len(cloud.volume)} nodes, dx = {cloud.grid_spacing:.6g} m, "
          f"horizon = {resolved['horizon']:.6g} m, node sets: {', '.join(resolved['node_sets'])}")
    print(f"{case_file}: {plan}")


def solve(case_json: str, *, solver: str | None = None, threads: int | None = None, quiet: bool = False,
          log: str | None = None, lock_fd: int | None = None,
          timeout: float | None = None) -> subprocess.CompletedProcess:
    """pdsolve on case_json: `solver` (default: $PDSOLVE, else build/solver/pdsolve: common/paths.py),
    with --threads `threads` when given and --quiet when asked. Its output goes to the file `log`
    (stdout and stderr together), else is captured as text in the result. lock_fd: the output
    folder's lock, handed to the solver (PD_LOCK_FD: it locks its folder itself, io/output_lock.hpp)
    so that the folder stays locked while it runs. The exit code (result.returncode, the command
    result.args) is the caller's to judge: peridyn, validation, bench and the tests each say it their
    own way. make runs pdsolve itself, with exec, so that a SIGTERM it passes on reaches the solver."""
    command = solve_command(case_json, solver=solver, threads=threads, quiet=quiet)
    handed = {} if lock_fd is None else {"pass_fds": (lock_fd,), "env": dict(os.environ, PD_LOCK_FD=str(lock_fd))}
    if log is None:
        return subprocess.run(command, capture_output=True, text=True, timeout=timeout, **handed)
    with open(log, "w", encoding="utf-8") as stream:
        return subprocess.run(command, stdout=stream, stderr=subprocess.STDOUT, timeout=timeout, **handed)


def solve_command(case_json: str, *, solver: str | None = None, threads: int | None = None,
                  quiet: bool = False) -> list[str]:
    """The command line of solve(), for a caller that shows it before it runs."""
    return [solver or pdsolve(), case_json] + (["--threads", str(threads)] if threads else []) \
        + (["--quiet"] if quiet else [])


def postprocess(out_dir: str, *, case_json: str | None = None, only: str | None = None, log=print) -> list[str]:
    """Figures and Gmsh views of a finished run in out_dir (postprocess/cli.py's run; `only`:
    "figures" or "gmsh"); returns the paths written."""
    from postprocess.cli import run

    return run(out_dir, case_json, only, log=log)


# ---------------------------------------------------------------- the checks of the stages

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
