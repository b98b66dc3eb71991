"""Turn a validated case plus its node cloud into the resolved case.json of formats.md §3."""
from __future__ import annotations

import difflib
import math

from .yaml_lines import CaseError

FORMAT_VERSION = 1
AXIS = {"x": 0, "y": 1, "z": 2}


def horizon_of(case: dict, grid_spacing: float) -> float:
    """δ from the case: an explicit horizon, else horizon_factor × dx (thesis §2.1: δ ≈ 3dx)."""
    disc = case["discretization"]
    if disc["horizon"] is not None:
        return disc["horizon"]
    dx = disc["dx"] if disc["dx"] is not None else grid_spacing
    return disc["horizon_factor"] * dx


def check_set_names(case: dict, existing: list[str]):
    """Every node set the case names must exist in the mesh; the message lists those that do."""
    path, lines = case["_path"], case["_lines"]
    problems = []

    def missing(name: str, keypath: tuple):
        if name in existing:
            return
        hint = difflib.get_close_matches(name, existing, n=1, cutoff=0.5)
        hint_text = f" (did you mean '{hint[0]}'?)" if hint else ""
        line = lines.get(keypath, lines.get(keypath[:-1], 1))
        problems.append(f"{path}:{line}: node set '{name}' is not a physical group of the mesh{hint_text}; "
                        f"the mesh has: {', '.join(sorted(existing)) or 'none'}")

    for i, bc in enumerate(case["boundary_conditions"]):
        missing(bc["set"], ("boundary_conditions", i, "set"))
    for i, ic in enumerate(case["initial_conditions"]):
        missing(ic["set"], ("initial_conditions", i, "set"))
    for i, name in enumerate(case["no_fail"]):
        missing(name, ("no_fail", i))
    for name in case["node_sets"]:
        missing(name, ("node_sets", name))
    for key in ("reactions", "probes"):
        for i, name in enumerate(case["output"][key]):
            missing(name, ("output", key, i))
    if isinstance(case["figures"]["probe"], str):
        missing(case["figures"]["probe"], ("figures", "probe"))
    if problems:
        raise CaseError("\n".join(problems))


def resolve(case: dict, *, node_sets: list[str], grid_spacing: float, nodes_file: str) -> dict:
    """The dictionary written to case.json, in SI units with every default explicit."""
    check_set_names(case, node_sets)
    # Every material key the case gives goes to the solver, which checks it against the model's
    # declared parameters (solver/src/materials/<model>/): a new model needs no edit here. An
    # optional key left out (None, e.g. no fracture_energy: unbreakable) is left out of case.json.
    blocks = [
        {"id": i + 1, "name": name, "model": m["model"], "density": m["density"],
         **{key: value for key, value in m.items() if key not in ("model", "density") and value is not None}}
        for i, (name, m) in enumerate(case["materials"].items())
    ]
    boundary = []
    for bc in case["boundary_conditions"]:
        for kind in ("displacement", "velocity", "body_force"):
            for comp, (times, values) in (bc[kind] or {}).items():
                boundary.append({"set": bc["set"], "kind": kind, "component": AXIS[comp],
                                 "times": times, "values": values})
    initial = []
    for ic in case["initial_conditions"]:
        for comp, (_times, values) in (ic["velocity"] or {}).items():
            initial.append({"set": ic["set"], "kind": "velocity", "component": AXIS[comp], "value": values[0]})
        # displacement + strain·x per component (strain: a uniform pre-strain, formats.md §3)
        shift = {comp: values[0] for comp, (_t, values) in (ic["displacement"] or {}).items()}
        strain = {comp: values[0] for comp, (_t, values) in (ic["strain"] or {}).items()}
        for comp in sorted(set(shift) | set(strain), key=AXIS.get):
            entry = {"set": ic["set"], "kind": "displacement", "component": AXIS[comp],
                     "value": shift.get(comp, 0.0)}
            if comp in strain:
                entry["gradient"] = strain[comp]
            initial.append(entry)
    contact = dict(case["contact"])
    if contact["skin"] is None:
        contact["skin"] = 0.5 * grid_spacing  # half the node spacing: few rebuilds, few extra pairs
    indenters = [_resolve_indenter(ind) for ind in case["indenters"]]
    time = dict(case["time"])
    figures = dict(case["figures"])
    figures["displacement_component"] = AXIS[figures["displacement_component"]]
    return {
        "format_version": FORMAT_VERSION,
        "case": case["_name"],
        "title": case["title"],
        "source": case["_path"],
        "nodes_file": nodes_file,
        "output_dir": ".",
        "dimension": case["dimension"],
        "analysis": case["analysis"],
        "thickness": case["thickness"],
        "grid_spacing": grid_spacing,
        "horizon": horizon_of(case, grid_spacing),
        "blocks": blocks,
        "no_fail_sets": list(case["no_fail"]),
        "node_sets": sorted(node_sets),
        "boundary_conditions": boundary,
        "initial_conditions": initial,
        "cracks": [{"from": _point3(c["from"]), "to": _point3(c["to"])} for c in case["cracks"]],
        "damping": case["damping"],
        "breaking_order": case["breaking_order"],
        "partial_volume": case["discretization"]["partial_volume"],
        "surface_correction": case["discretization"]["surface_correction"],
        "contact": contact,
        "indenters": indenters,
        "time": time,
        "adaptive": dict(case["adaptive"]),
        "quasi_static": dict(case["quasi_static"]),
        "implicit": dict(case["implicit"]),
        "mixed": dict(case["mixed"]),
        "output": dict(case["output"]),
        "figures": figures,
    }


def _point3(point: list[float]) -> list[float]:
    """[x, y] or [x, y, z] as [x, y, z] (z = 0 in 2D)."""
    return [float(c) for c in point] + [0.0] * (3 - len(point))


def _unit(vector: list[float]) -> list[float]:
    norm = math.sqrt(sum(c * c for c in vector))
    return [c / norm for c in vector]


def _resolve_indenter(ind: dict) -> dict:
    """Every key explicit; directions as unit vectors (the solver checks them again)."""
    out = {"name": ind["name"], "shape": ind["shape"], "centre": ind["centre"],
           "velocity": ind["velocity"] or [0.0, 0.0, 0.0], "stiffness": ind["stiffness"]}
    if ind["shape"] == "plane":
        out["normal"] = _unit(ind["normal"])
    else:
        out["radius"] = ind["radius"]
    if ind["shape"] == "cylinder":
        out["axis"] = _unit(ind["axis"] or [0.0, 0.0, 1.0])
    return out
