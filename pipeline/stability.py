"""Checks of a discretized case before the solver runs: bonds per node and the stable time step.

Hand-edited case files mix units (g/cm³ for kg/m³, MPa or GPa for Pa, mm for m). Each mistake
moves the stable time step of thesis eq. 2.5 by orders of magnitude, so the run either never
ends (10¹² steps) or is over in a single step. The step is the solver's own (`pdsolve --physics`,
asked through pipeline/solver_physics.py on the node cloud and the resolved case, partial volumes,
contact springs, LPS and surface corrections included), so such a mistake becomes an error before
any work, naming the file, the line and the key. Messages that could be false alarms are warnings.
"""
from __future__ import annotations

import os

import numpy as np
from scipy.spatial import cKDTree

from .solver_physics import CaseQuery
from .yaml_lines import CaseError

# A run needing more steps than this is a unit mistake, not a plan: at 10⁸ node-steps per second
# it would take years for even a small cloud.
MAX_STEPS = 1.0e9
# The solver's bond rule |ξ| ≤ δ·(1 + 1e-12) (solver/README.md).
BOND_SLACK = 1.0 + 1e-12
# Densities [kg/m³] and moduli [Pa] below these look like g/cm³ and MPa/GPa: warned about only,
# since foams and gels are real.
MIN_HORIZON_RATIO = 2.0   # horizon / spacing below which a warning says the model is a lattice
LOW_DENSITY = 50.0
LOW_MODULUS = 1.0e5


def _where(case: dict, *keypath) -> str:
    """'file:line: key' for messages; a key absent from the file takes its section's line."""
    lines = case.get("_lines", {})
    path = tuple(keypath)
    while path and path not in lines:
        path = path[:-1]
    dotted = ".".join(str(p) for p in keypath)
    return f"{case.get('_path', '<case>')}:{lines.get(path, 1)}: {dotted}"


def _fmt(p) -> str:
    return "(" + ", ".join(f"{v:.6g}" for v in p) + ")"


def check_discretized_case(case: dict, resolved: dict, cloud, query: CaseQuery | None = None) -> list[str]:
    """Raise CaseError for a case that cannot run sensibly; return warnings (strings) otherwise.

    case: the validated case (pipeline.case.load_case); resolved: its case.json dictionary
    (pipeline.resolve); cloud: the NodeCloud it was resolved against; query: the solver's answer
    for them (solver_physics.CaseQuery; made here if not given), asked only once the horizon checks
    have passed. Raises solver_physics.SolverError when pdsolve is missing or cannot answer.
    """
    warnings: list[str] = []
    errors: list[str] = []
    horizon = float(resolved["horizon"])
    dx = float(resolved["grid_spacing"])
    horizon_key = ("discretization", "horizon" if case["discretization"]["horizon"] is not None
                   else "horizon_factor")
    if not horizon >= dx:
        raise CaseError(f"{_where(case, *horizon_key)}: the horizon {horizon:.6g} m is smaller than the node "
                        f"spacing {dx:.6g} m: no node would have a bond; use about 3 × the spacing")

    names = list(case["materials"])
    for name in names:
        m = case["materials"][name]
        if m["density"] < LOW_DENSITY:
            warnings.append(f"{_where(case, 'materials', name, 'density')}: {m['density']:g} kg/m³ is lighter "
                            f"than most foams; was it given in g/cm³? (SI: kg/m³, e.g. 7850 for steel)")
        if m["youngs_modulus"] is not None and m["youngs_modulus"] < LOW_MODULUS:
            warnings.append(f"{_where(case, 'materials', name, 'youngs_modulus')}: {m['youngs_modulus']:g} Pa "
                            f"is softer than rubber; was it given in MPa or GPa? (SI: Pa, e.g. 2.1e11 for steel)")

    points = np.asarray(cloud.points)
    block = np.asarray(cloud.block, dtype=np.int64)
    tree = cKDTree(points)
    # Isolated nodes: no partner within the horizon, so no force ever acts on them.
    dist, _ = tree.query(points, k=2, distance_upper_bound=horizon * BOND_SLACK)
    isolated = ~np.isfinite(dist[:, 1])
    if np.all(isolated):
        raise CaseError(f"{_where(case, *horizon_key)}: no node has a bond: every neighbour lies farther than "
                        f"the horizon {horizon:.6g} m; use a horizon of about 3 × the node spacing")
    if np.any(isolated):
        first = int(np.nonzero(isolated)[0][0])
        warnings.append(f"{_where(case, *horizon_key)}: {int(isolated.sum())} node(s) have no bond (no other node "
                        f"within the horizon {horizon:.6g} m), e.g. node {first} at {_fmt(points[first])}; "
                        f"no force acts on them: refine the mesh there or enlarge the horizon")

    # A horizon of about one spacing leaves a node 4 (2D) or 6 (3D) bonds: a lattice of springs,
    # not the peridynamic continuum (thesis §2.1 uses δ ≈ 3·dx; issue 17, item 10). An error since
    # issue 39 (item 7): a case with `horizon` in metres, coarsened by changing dx alone, ran at
    # δ = 1 dx after this was only a warning, and its result meant nothing. FORCE=1 runs it anyway.
    if horizon < MIN_HORIZON_RATIO * dx:
        sample = np.linspace(0, len(points) - 1, min(len(points), 5000)).astype(np.int64)
        bonds = tree.query_ball_point(points[sample], horizon * BOND_SLACK, return_length=True) - 1
        fixed = horizon_key[1] == "horizon"
        text = (f"{_where(case, *horizon_key)}: the horizon {horizon:.6g} m is {horizon / dx:.3g} × the node "
                f"spacing {dx:.6g} m: {float(np.mean(bonds)):.3g} bonds per node on average; the peridynamic "
                f"model needs a horizon of about 3 × the spacing (thesis §2.1): "
                + (f"discretization.horizon is fixed in metres, so it did not follow dx: remove it and let "
                   f"horizon_factor (3.015 by default) set δ = 3.015 dx = {3.015 * dx:.6g} m, or give a horizon "
                   f"≥ {MIN_HORIZON_RATIO * dx:.6g} m" if fixed else "use horizon_factor: 3.015"))
        if os.environ.get("FORCE") == "1":
            warnings.append(text + " (run anyway: FORCE=1)")
        else:
            raise CaseError(text + "; FORCE=1 (make FORCE=1 case=...) runs it anyway")

    dt_stable, node = (query or CaseQuery(resolved, cloud)).stable_step()
    if node < 0:  # no sampled node has a bond; the isolated-node warning says so
        return warnings
    time = case["time"]
    end = float(time["end"])
    fixed = not isinstance(time["dt"], str)
    dt = float(time["dt"]) if fixed else dt_stable * float(time["safety_factor"])
    material = names[int(block[node]) - 1]
    m = case["materials"][material]
    origin = (f"thesis eq. 2.5 gives a stable step of {dt_stable:.3g} s at node {node} {_fmt(points[node])}, "
              f"from material '{material}' ({_where(case, 'materials', material)}): ρ = {m['density']:g} kg/m³, "
              + (f"E = {m['youngs_modulus']:g} Pa" if m["youngs_modulus"] is not None
                 else f"c = {m['micromodulus']:g} N/m⁶")
              + (f", ν = {m['poisson_ratio']:g} (LPS)" if m.get("model") == "lps" else "")
              + f", with horizon {horizon:.6g} m")
    units = "check the units (SI: kg/m³, Pa, m, s)"
    steps = end / dt
    if steps > MAX_STEPS:
        key = ("time", "dt") if fixed else ("time", "end")
        errors.append(f"{_where(case, *key)}: the run would need {steps:.3g} steps of {dt:.3g} s to reach "
                      f"time.end = {end:g} s (more than {MAX_STEPS:.0e}); {origin}; {units}")
    if not fixed and end < dt_stable:
        errors.append(f"{_where(case, 'time', 'end')}: time.end = {end:g} s is shorter than one stable time "
                      f"step: {origin}; nothing can happen in such a run; {units}")
    if time["dt"] == "exact" and float(time["safety_factor"]) > 1.0:
        warnings.append(f"{_where(case, 'time', 'safety_factor')}: {float(time['safety_factor']):g} > 1 with "
                        "time.dt: exact makes the step larger than the exact stability limit 2/ω_max: the run "
                        "will blow up; use a safety_factor of at most 1")
    elif not fixed and float(time["safety_factor"]) > 1.0:
        warnings.append(f"{_where(case, 'time', 'safety_factor')}: {float(time['safety_factor']):g} > 1 makes the step "
                        f"{dt:.3g} s larger than the stable step of eq. 2.5: {origin}; the run may blow up "
                        "(the exact limit is time.dt: exact): use a safety_factor of at most 1")
    if fixed and dt > dt_stable:
        warnings.append(f"{_where(case, 'time', 'dt')}: {dt:g} s exceeds the stable step: {origin}; the run "
                        f"will likely blow up; use dt: stable")
    if errors:
        raise CaseError("\n".join(errors))
    return warnings
