"""The body a case's .geo describes, checked before gmsh meshes it (issue 17, items 10 and 11).

Three checks, each an error naming the case file's line:
- check_lengths: a gmsh parameter that the .geo labels as a length ("[m]" in its DefineConstant
  Name) must be > 0. gmsh takes any number: `a: -0.005` meshed the same hole as 0.005, and a
  zero mesh size falls back to gmsh's default.
- check_body: the geometry, built with the gmsh API (preprocess/geo_probe.py) but not meshed, has
  a body of the case's dimension; every physical group the case uses exists and holds entities;
  gmsh reported no error while building it; and every inner loop of a surface (a hole) lies inside
  its outer loop. A hole radius larger than the plate (plate_with_hole `a: 0.06`) made gmsh mesh
  the disk around the plate instead, without a word; `a: 0.03` crossed the plate's edge and gmsh
  failed only while meshing, naming neither the case file nor the parameter.
- check_mesh_cost: the mesh's size estimated from the body's bounding box and the .geo's mesh size,
  and the lattice's from discretization.dx, against pipeline/cost.py's limits (more than MAX_HOURS,
  or more than half of the free memory or disk); FORCE=1 runs it anyway. `lc: 2e-6` meshed for ever.
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys

from common.memory import available_memory
from common.paths import PYTHON, REPOSITORY

from .cost import MAX_HOURS, MEMORY_PER_BOND, MEMORY_PER_NODE, _duration, _free_disk
from .resolve import check_set_names
from .yaml_lines import CaseError

PROBE_TIMEOUT = 120.0  # s: building a shipped case's geometry takes well under 1 s

# gmsh's cost, measured with `gmsh -2` on plate_with_hole (lc = 3e-4 m: 65,340 nodes, 3.5 s of CPU,
# a peak of 141 MB, a 6.3 MB .msh; lc = 4e-4 m: 36,508 nodes, 102 MB): nodes per CPU second, bytes
# of memory per node (the slope between the two), bytes of .msh per node.
GMSH_NODE_RATE = 1.9e4
GMSH_BYTES_PER_NODE = 1.4e3
MSH_BYTES_PER_NODE = 97.0
# Area (2D) or volume (3D) per node of a mesh of size h: an equilateral triangle has area √3/4·h²
# and a mesh has about two triangles per node; a regular tetrahedron has volume h³/(6√2) and a mesh
# about six tetrahedra per node.
AREA_PER_NODE = math.sqrt(3.0) / 2.0
VOLUME_PER_NODE = 6.0 / (6.0 * math.sqrt(2.0))


def _line(case: dict, name: str | None = None) -> int:
    lines = case["_lines"]
    if name is not None and ("geometry", "parameters", name) in lines:
        return lines[("geometry", "parameters", name)]
    return lines.get(("geometry", "parameters"), lines.get(("geometry",), 1))


def check_lengths(case: dict, geo: str):
    """Every parameter that the .geo labels as a length is > 0."""
    from preprocess.geo_guard import geo_lengths

    lengths = geo_lengths(geo)
    errors = []
    for name, value in case["geometry"]["parameters"].items():
        if name in lengths and value is not None and not value > 0:
            errors.append(f"{case['_path']}:{_line(case, name)}: geometry.parameters.{name}: {value:g} m, but "
                          f"{os.path.basename(geo)} says '{name}' is a length ({lengths[name]}): give a "
                          "length > 0")
    if errors:
        raise CaseError("\n".join(errors))


def probe_geometry(case: dict, geo: str) -> dict:
    """preprocess/geo_probe.py's description of the body, in a subprocess with a time limit."""
    from preprocess import sandbox

    parameters = case["geometry"]["parameters"]
    real = os.path.realpath(geo)
    # gmsh.open parses the .geo as gmsh does (a SystemCall there would run): in the sandbox too,
    # with the case folder and the Python code the probe imports read-only, and nothing writable.
    # Debian's python3 (in /usr), the one the sandbox holds, with python3-gmsh.
    python = sys.executable if sys.executable.startswith("/usr/") or not sandbox.enabled() else PYTHON
    command = [python, "-m", "preprocess.geo_probe", real, str(case["dimension"]), json.dumps(parameters)]
    code = [os.path.join(REPOSITORY, package) for package in ("common", "preprocess")]
    try:
        result = sandbox.run(command, geo, read_only=[os.path.dirname(real), *code], cwd=REPOSITORY,
                             timeout=PROBE_TIMEOUT)
    except subprocess.TimeoutExpired:
        raise CaseError(f"{case['_path']}:{_line(case)}: gmsh did not build the geometry of {geo} within "
                        f"{PROBE_TIMEOUT:g} s; check the .geo and its parameters") from None
    if result.returncode != 0:
        tail = "\n  ".join((result.stderr or result.stdout).strip().splitlines()[-5:])
        raise CaseError(f"{case['_path']}:{_line(case)}: gmsh could not build the geometry of {geo} with "
                        f"these parameters:\n  {tail}")
    return json.loads(result.stdout)


def _inside(inner: list, outer: list, dimension: int) -> bool:
    """Is box `inner` inside box `outer` (up to a rounding error of the body's size)?"""
    size = max(outer[i + 3] - outer[i] for i in range(dimension))
    tolerance = 1e-9 * size
    return all(inner[i] >= outer[i] - tolerance and inner[i + 3] <= outer[i + 3] + tolerance
               for i in range(dimension))


def _outside_points(points, polygon, tolerance: float) -> int:
    """How many of `points` lie outside `polygon` (both [[x, y], ...]) by more than `tolerance`:
    an even-odd ray cast, with points within `tolerance` of an edge counted as inside."""
    import numpy as np

    p = np.asarray(points, dtype=float)
    a = np.asarray(polygon, dtype=float)
    b = np.roll(a, -1, axis=0)
    x, y = p[:, 0:1], p[:, 1:2]
    crosses = ((a[:, 1] > y) != (b[:, 1] > y)) & \
        (x < (b[:, 0] - a[:, 0]) * (y - a[:, 1]) / np.where(b[:, 1] == a[:, 1], 1.0, b[:, 1] - a[:, 1]) + a[:, 0])
    inside = crosses.sum(axis=1) % 2 == 1
    d = b - a
    length2 = np.maximum((d ** 2).sum(axis=1), 1e-300)
    s = np.clip(((x - a[:, 0]) * d[:, 0] + (y - a[:, 1]) * d[:, 1]) / length2, 0.0, 1.0)
    distance = np.hypot(x - (a[:, 0] + s * d[:, 0]), y - (a[:, 1] + s * d[:, 1])).min(axis=1)
    return int(np.count_nonzero(~inside & (distance > tolerance)))


def check_body(case: dict, geo: str, probe: dict):
    """The body exists, its groups are there and not empty, gmsh built it without an error, holes
    lie inside their outer boundary."""
    dim, path = case["dimension"], case["_path"]
    names = ", ".join(f"{k} = {v:g}" for k, v in case["geometry"]["parameters"].items())
    given = f" with {names}" if names else ""
    where = f"{path}:{_line(case)}"
    errors = []
    gmsh_errors = [e for e in probe["errors"] if e.startswith("Error")]
    if gmsh_errors:
        errors.append(f"{where}: gmsh reported an error building {geo}{given}:\n  " + "\n  ".join(gmsh_errors[:10])
                      + "\n  check these parameters")
    if not probe["entities"]:
        errors.append(f"{where}: {geo}{given} makes no {'surface' if dim == 2 else 'volume'}: the body is empty "
                      f"(a dimension-{dim} case needs a body of dimension {dim})")
    for entity in probe["entities"]:
        outer, inner = entity["loop_boxes"][0], entity["loop_boxes"][1:]
        for k, box in enumerate(inner):
            if box is not None and outer is not None and not _inside(box, outer, dim):
                what = "surface" if dim == 2 else "volume"
                errors.append(f"{where}: in {geo}{given}, {what} {entity['tag']} has a hole (its boundary "
                              f"{entity['loops'][k + 1]}) that reaches outside its outer boundary "
                              f"{entity['loops'][0]}: a hole larger than the body or crossing its edge "
                              f"(hole x {box[0]:g}…{box[3]:g}, y {box[1]:g}…{box[4]:g}; body x {outer[0]:g}…"
                              f"{outer[3]:g}, y {outer[1]:g}…{outer[4]:g}); make the hole smaller or the body larger")
            elif dim == 2 and "loop_points" in entity:
                # Inside the outer loop's box but perhaps not inside the loop (an L-shaped plate
                # with the hole in its missing corner: gmsh meshes that without a word).
                size = max(outer[3] - outer[0], outer[4] - outer[1])
                out = _outside_points(entity["loop_points"][k + 1], entity["loop_points"][0], 1e-6 * size)
                if out:
                    errors.append(f"{where}: in {geo}{given}, surface {entity['tag']} has a hole (its boundary "
                                  f"{entity['loops'][k + 1]}) partly or wholly outside its outer boundary "
                                  f"{entity['loops'][0]} ({out} of {len(entity['loop_points'][k + 1])} points of the "
                                  "hole's outline lie outside the body): move the hole into the body or make it smaller")
    groups = probe["groups"]
    lines = case["_lines"]
    for name in case["materials"]:
        line = lines.get(("materials", name), 1)
        if name in groups and (groups[name][0] != dim or groups[name][1] == 0):
            how = "has no entities" if groups[name][1] == 0 else f"is of dimension {groups[name][0]}, not {dim}"
            errors.append(f"{path}:{line}: materials.{name}: the physical group '{name}' of {geo} {how}: "
                          f"a material needs a {'surface' if dim == 2 else 'volume'} group that holds the body")
        elif name not in groups:
            top = [g for g, (d, n) in groups.items() if d == dim]
            errors.append(f"{path}:{line}: materials.{name}: {geo} has no physical group '{name}'; its "
                          f"{dim}D groups are: {', '.join(top) or 'none'}")
    empty = [g for g, (_, n) in groups.items() if n == 0]
    try:
        check_set_names(case, [g for g in groups if g not in empty])
    except CaseError as error:
        errors.append(str(error).replace("of the mesh", f"of {geo} (or has no entities)"))
    if errors:
        raise CaseError("\n".join(errors))


def mesh_size(case: dict, geo: str, probe: dict) -> float | None:
    """The smallest of the .geo's "mesh size" parameters (the case's value, else the .geo's
    default) scaled and bounded as gmsh's Mesh.MeshSize* options say; None if the .geo labels none."""
    from preprocess.geo_guard import geo_lengths

    parameters = case["geometry"]["parameters"]
    sizes = []
    for name, label in geo_lengths(geo).items():
        if "mesh size" not in label.lower():
            continue
        value = parameters.get(name, probe["numbers"].get(label))
        if value is not None and value > 0:
            sizes.append(float(value))
    if not sizes:
        return None
    options = probe["size_options"]
    h = min(sizes) * options["MeshSizeFactor"]
    return min(max(h, options["MeshSizeMin"]), options["MeshSizeMax"])


def estimate_mesh(case: dict, geo: str, probe: dict) -> dict:
    """Mesh and lattice nodes from the body's bounding box (an upper bound of its area or volume)."""
    dim = case["dimension"]
    box = probe["bbox"]
    extent = [max(box[i + 3] - box[i], 0.0) for i in range(dim)]
    measure = math.prod(extent)
    h = mesh_size(case, geo, probe)
    mesh_nodes = measure / ((AREA_PER_NODE if dim == 2 else VOLUME_PER_NODE) * h ** dim) if h else None
    disc = case["discretization"]
    lattice_nodes = bonds = None
    if disc["method"] == "lattice" and disc["dx"]:
        dx = float(disc["dx"])
        lattice_nodes = math.prod(e / dx + 1.0 for e in extent)
        m = float(disc["horizon"]) / dx if disc["horizon"] else float(disc["horizon_factor"])
        bonds = lattice_nodes * (math.pi * m * m if dim == 2 else 4.0 / 3.0 * math.pi * m ** 3)
    return {"mesh_size": h, "mesh_nodes": mesh_nodes, "lattice_nodes": lattice_nodes, "bonds": bonds,
            "measure": measure}


def _gmsh_over_limits(n: float, memory: float, disk: float) -> list[str]:
    """What a gmsh mesh of n nodes would go beyond: MAX_HOURS, half of the memory or of the disk."""
    seconds, need, size = n / GMSH_NODE_RATE, n * GMSH_BYTES_PER_NODE, n * MSH_BYTES_PER_NODE
    found = []
    if seconds > MAX_HOURS * 3600:
        found.append(f"meshing would take about {_duration(seconds)} (more than {MAX_HOURS:g} h)")
    if need > 0.5 * memory:
        found.append(f"gmsh would need about {need / 1e6:.0f} MB, more than half of the {memory / 1e6:.0f} MB "
                     "available")
    if size > 0.5 * disk:
        found.append(f"the mesh file would be about {size / 1e6:.3g} MB, more than half of the {disk / 1e6:.3g} MB free")
    return found


def check_mesh_growth(case: dict, geo: str, probe: dict, out_dir: str, force: bool | None = None):
    """The estimate above trusts the .geo's labelled mesh size; a mesh size field (`Field[1] =
    MathEval; Field[1].F = "2e-6"; Background Field = 1;`) or a point's size bypassed it (722 nodes
    estimated, then gmsh meshed until the time limit). The probe meshed the boundary (its curves in
    2D, its surfaces in 3D) with everything the .geo sets: at that mean element size h, the body
    (its bounding box, an upper bound) would have measure / (area or volume per node at h) nodes;
    above check_mesh_cost's limits this is a CaseError naming the .geo, the boundary's mesh and the
    estimate, unless FORCE=1."""
    force = os.environ.get("FORCE") == "1" if force is None else force
    boundary = probe.get("boundary")
    if force or not boundary or not boundary["size"]:
        return
    dim = case["dimension"]
    est = estimate_mesh(case, geo, probe)
    h = boundary["size"]
    n = est["measure"] / ((AREA_PER_NODE if dim == 2 else VOLUME_PER_NODE) * h ** dim)
    found = _gmsh_over_limits(n, available_memory(), _free_disk(out_dir))
    if not found:
        return
    what = "curves" if dim == 2 else "surfaces"
    said = (f"the estimate from the case's mesh size {est['mesh_size']:g} m was about {est['mesh_nodes']:.3g} nodes"
            if est["mesh_nodes"] is not None else "the .geo labels no mesh size")
    raise CaseError(f"{case['_path']}:{_line(case)}: {geo}: gmsh meshed the body's {what} with {boundary['nodes']} "
                    f"nodes, {h:.3g} m apart on average ({said}); at that size the {dim}D mesh would have about "
                    f"{n:.3g} nodes: " + "; ".join(found) + ": a mesh size field (Field, Background Field) or the "
                    "size of a point makes the mesh finer than the mesh size says; coarsen it, or run it anyway "
                    "with FORCE=1 (make FORCE=1 case=...)")


def check_mesh_cost(case: dict, geo: str, probe: dict, out_dir: str, force: bool | None = None) -> str | None:
    """CaseError (naming the mesh size's or dx's line, the estimate and FORCE=1) above a limit."""
    force = os.environ.get("FORCE") == "1" if force is None else force
    est = estimate_mesh(case, geo, probe)
    memory, disk = available_memory(), _free_disk(out_dir)
    reasons, parts = [], []
    where = None
    lines = case["_lines"]
    if est["mesh_nodes"] is not None:
        n = est["mesh_nodes"]
        seconds = n / GMSH_NODE_RATE
        need = n * GMSH_BYTES_PER_NODE
        parts.append(f"gmsh: about {n:.3g} mesh nodes at mesh size {est['mesh_size']:g} m, {_duration(seconds)}, "
                     f"{need / 1e6:.0f} MB of memory, {n * MSH_BYTES_PER_NODE / 1e6:.0f} MB of .msh")
        size_names = [k for k in case["geometry"]["parameters"] if "mesh" in k.lower() or k == "lc"]
        line = _line(case, size_names[0] if size_names else None)
        found = _gmsh_over_limits(n, memory, disk)
        if found:
            reasons += found
            where = (line, "make the mesh size larger (for a lattice case the mesh only outlines the body: "
                     "a few elements across its smallest feature are enough)")
    if est["lattice_nodes"] is not None:
        n, bonds = est["lattice_nodes"], est["bonds"]
        need = n * MEMORY_PER_NODE + bonds * MEMORY_PER_BOND
        parts.append(f"lattice: at most {n:.3g} nodes and {bonds:.3g} bonds, {need / 1e6:.0f} MB of memory")
        if need > 0.5 * memory:
            reasons.append(f"the lattice would need about {need / 1e6:.0f} MB, more than half of the "
                           f"{memory / 1e6:.0f} MB available")
            if where is None:
                where = (lines.get(("discretization", "dx"), 1), "coarsen discretization.dx")
    plan = "estimate before meshing: " + "; ".join(parts) if parts else None
    if reasons and not force:
        line, fix = where
        raise CaseError(f"{case['_path']}:{line}: {plan}; " + "; ".join(reasons) + f": {fix}, or run it anyway "
                        "with FORCE=1 (make FORCE=1 case=...)")
    return plan
