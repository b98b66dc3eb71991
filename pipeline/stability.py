"""Checks of a discretized case before the solver runs: bonds per node and the stable time step.

Hand-edited case files mix units (g/cm³ for kg/m³, MPa or GPa for Pa, mm for m). Each mistake
moves the stable time step of thesis eq. 2.5 by orders of magnitude, so the run either never
ends (10¹² steps) or is over in a single step. Computing that step here, from the node cloud and
the materials as the solver will (partial volumes and contact springs included; tested equal to
`pdsolve --stable-dt`), turns such a mistake into an error before any work,
naming the file, the line and the key. Messages that could be false alarms are warnings.
"""
from __future__ import annotations

import math
import os

import numpy as np
from scipy.spatial import cKDTree

from . import surface_correction
from .yaml_lines import CaseError

# A run needing more steps than this is a unit mistake, not a plan: at 10⁸ node-steps per second
# it would take years for even a small cloud.
MAX_STEPS = 1.0e9
# Stable steps are computed exactly (the solver's eq. 2.5 sum) on at most this many nodes; the
# minimum over a subset is an upper bound of the solver's, so "too many steps" is never a false alarm.
SAMPLE = 20000
# The solver's bond rule |ξ| ≤ δ·(1 + 1e-12) (solver/README.md).
BOND_SLACK = 1.0 + 1e-12
# Densities [kg/m³] and moduli [Pa] below these look like g/cm³ and MPa/GPa: warned about only,
# since foams and gels are real.
MIN_HORIZON_RATIO = 2.0   # horizon / spacing below which a warning says the model is a lattice
LOW_DENSITY = 50.0
LOW_MODULUS = 1.0e5
# partial_volume rule → (family extension beyond δ in units of dx, shell weight ν on the outer
# shell), as solver/src/core/partial_volume.cpp registers them (docs/theory.md T5).
PARTIAL_VOLUME = {"none": (0.0, False), "lammps": (0.0, True), "hhb": (0.5, True)}
# Contact distance 2r_s = 1.35·dx (solver/src/core/work_plan.cpp plan_contact; docs/theory.md T8).
CONTACT_DISTANCE = 1.35


def micromodulus(analysis: str, youngs_modulus: float, horizon: float, thickness: float | None) -> float:
    """c of docs/theory.md T2 (thesis eq. 1.11), as solver/src/core/material.cpp computes it."""
    if analysis == "3d":
        return 12.0 * youngs_modulus / (math.pi * horizon ** 4)
    if analysis == "plane_stress":
        return 9.0 * youngs_modulus / (math.pi * thickness * horizon ** 3)
    if analysis == "plane_strain":
        return 48.0 * youngs_modulus / (5.0 * math.pi * thickness * horizon ** 3)
    raise ValueError(f"unknown analysis {analysis!r}")


def block_micromodulus(case: dict, material: dict, horizon: float) -> float:
    """c of one material of a validated case: given directly (micromodulus), or from E (F1)."""
    if material.get("micromodulus") is not None:
        return float(material["micromodulus"])
    return micromodulus(case["analysis"], material["youngs_modulus"], horizon, case["thickness"])


def lps_moduli(analysis: str, youngs_modulus: float, poisson_ratio: float) -> tuple[float, float]:
    """(κ, μ) of an LPS block, as solver/src/materials/lps/lps_constants.cpp: κ the bulk modulus in 3D,
    the in-plane bulk modulus in 2D."""
    e, nu = youngs_modulus, poisson_ratio
    mu = e / (2.0 * (1.0 + nu))
    if analysis == "plane_strain":
        return e / (2.0 * (1.0 + nu) * (1.0 - 2.0 * nu)), mu
    if analysis == "plane_stress":
        return e / (2.0 * (1.0 - nu)), mu
    return e / (3.0 * (1.0 - 2.0 * nu)), mu


def influence(kind: str, length: np.ndarray, horizon: float) -> np.ndarray:
    """ω(|ξ|) of solver/src/materials/lps/lps_constants.cpp."""
    if kind == "inverse_length":
        return 1.0 / length
    if kind == "gaussian":
        return np.exp(-(length * length) / (horizon * horizon))
    return np.ones_like(length)


def lps_micromodulus(analysis: str, kappa: float, horizon: float, thickness: float | None) -> float:
    """The bond-based c of the same κ, which contact uses: 18K/(πδ⁴) (3D), 12κ/(πhδ³) (2D)."""
    if analysis == "3d":
        return 18.0 * kappa / (math.pi * horizon ** 4)
    return 12.0 * kappa / (math.pi * thickness * horizon ** 3)


def contact_stiffness_factor(resolved: dict, block: np.ndarray) -> float | None:
    """c_s/c when the solver will compute contact pairs for this case and cloud, else None
    (solver/src/core/work_plan.cpp plan_contact: on; or auto with several blocks or self_contact)."""
    contact = resolved["contact"]
    on = contact["enabled"] == "on" or (contact["enabled"] == "auto" and
                                        (len(np.unique(block)) > 1 or contact["self_contact"]))
    return float(contact["stiffness_factor"]) if on else None


def stable_time_step(points: np.ndarray, volume: np.ndarray, block: np.ndarray, density: np.ndarray,
                     c_pair: np.ndarray, horizon: float, tree: cKDTree | None = None, *,
                     dx: float | None = None, partial_volume: str = "none", contact: float | None = None,
                     sample: int | None = SAMPLE, lps: tuple | None = None,
                     surface: np.ndarray | tuple | None = None) -> tuple[float, int]:
    """min over nodes of √(2ρ_i / Σ_j V_j ν_ij c_ij/|ξ_ij|) (thesis eq. 2.5; docs/theory.md T10) and the
    node where it is reached, as solver/src/core/model.cpp stable_time_step computes it: ν of the
    `partial_volume` rule (needs the grid spacing dx unless "none"), and with contact (c_s/c given
    as `contact`, see contact_stiffness_factor) a spring V_j c_s c_ij/δ for every bond with
    |ξ| ≤ 1.35·dx. Over an evenly spread subset of `sample` nodes for larger clouds (None: all).
    block is 1-based; density[b-1] and c_pair[a-1, b-1] (the solver's arithmetic mean of the two
    blocks' c). (inf, -1) when no sampled node has a bond. lps = (q, kind): an LPS case, whose bond
    term is V_j ν ω(|ξ|)(q_i + q_j) with q = (d²κ + α)/m per node (LpsModel::bond_stiffness).
    surface: the per-node direction factors of the energy surface correction (n × 3,
    surface_correction.direction_factors or split_factors), or (family volumes V_i, V0) of the
    volume method: each bond's term times its g (core/model.cpp node_stiffness; LPS's q is unchanged
    by either: its κ, α and m all scale by ḡ_i).
    tests/pipeline/test_stability_solver.py
    holds it equal to `pdsolve --stable-dt` on every shipped case."""
    n = len(points)
    tree = tree if tree is not None else cKDTree(points)
    extension, shell = PARTIAL_VOLUME[partial_volume]
    cutoff = horizon + extension * dx if extension else horizon
    sample = np.arange(n) if sample is None or n <= sample else np.unique(np.linspace(0, n - 1, sample).astype(np.int64))
    pairs = cKDTree(points[sample]).sparse_distance_matrix(tree, cutoff * BOND_SLACK, output_type="coo_matrix")
    rows, cols, dist = pairs.row, pairs.col, pairs.data
    keep = dist > 0  # the node itself (coincident nodes are rejected earlier)
    rows, cols, dist = rows[keep], cols[keep], dist[keep]
    i = sample[rows]
    c = c_pair[block[i] - 1, block[cols] - 1]
    # ν = clamp((δ + dx/2 − |ξ|)/dx, 0, 1) on the outer shell (core/bonds.hpp VolumeWeight)
    nu = np.clip((horizon + 0.5 * dx - dist) * (1.0 / dx), 0.0, 1.0) if shell else 1.0
    if lps is None:
        stiffness = volume[cols] * nu * c / dist
    else:
        q, kind = lps
        stiffness = volume[cols] * nu * influence(kind, dist, horizon) * (q[i] + q[cols])
    if isinstance(surface, tuple):  # the volume method: g = 2 V0/(V_i + V_j)
        family, bulk = surface
        stiffness = stiffness * (2.0 * bulk / (family[i] + family[cols]))
    elif surface is not None:
        stiffness = stiffness * surface_correction.bond_factors(surface, i, cols, (points[cols] - points[i]) / dist[:, None])
    if contact is not None:
        stiffness = stiffness + np.where(dist <= CONTACT_DISTANCE * dx, volume[cols] * contact * c / horizon, 0.0)
    total = np.bincount(rows, weights=stiffness, minlength=len(sample))
    bonded = total > 0
    if not np.any(bonded):
        return math.inf, -1
    dt = np.full(len(sample), np.inf)
    dt[bonded] = np.sqrt(2.0 * density[block[sample[bonded]] - 1] / total[bonded])
    k = int(np.argmin(dt))
    return float(dt[k]), int(sample[k])


def case_stable_time_step(case: dict, resolved: dict, cloud, tree: cKDTree | None = None, *,
                          sample: int | None = SAMPLE) -> tuple[float, int]:
    """stable_time_step for a validated case, its case.json dictionary and its node cloud: the
    step the solver's run.log reports before the safety factor (`pdsolve --stable-dt`)."""
    names = list(case["materials"])
    horizon = float(resolved["horizon"])
    materials = [case["materials"][n] for n in names]
    block = np.asarray(cloud.block, dtype=np.int64)
    lps = None
    if materials[0]["model"] == "lps":
        moduli = [lps_moduli(case["analysis"], m["youngs_modulus"], m["poisson_ratio"]) for m in materials]
        c = np.array([lps_micromodulus(case["analysis"], k, horizon, case["thickness"]) for k, _ in moduli])
        kind = materials[0].get("influence") or "one"
        lps = (lps_node_terms(cloud, block, moduli, case["analysis"], horizon, kind, resolved, tree), kind)
    else:
        c = np.array([block_micromodulus(case, m, horizon) for m in materials])
    c_pair = 0.5 * (c[:, None] + c[None, :])
    density = np.array([m["density"] for m in materials], dtype=np.float64)
    surface = None
    method = resolved.get("surface_correction", "none")
    if method != "none":
        law = {"model": "pmb", "c": c, "c_pair": c_pair} if lps is None else \
            {"model": "lps", "moduli": moduli, "kind": lps[1]}
        surface, q = surface_factors(case, resolved, cloud, block, law, tree, method)
        if q is not None:
            lps = (q, lps[1])
    return stable_time_step(np.asarray(cloud.points), np.asarray(cloud.volume), block, density, c_pair,
                            horizon, tree, dx=float(resolved["grid_spacing"]),
                            partial_volume=resolved["partial_volume"],
                            contact=contact_stiffness_factor(resolved, block), sample=sample, lps=lps,
                            surface=surface)


def surface_factors(case: dict, resolved: dict, cloud, block: np.ndarray, law: dict,
                    tree: cKDTree | None = None, method: str = "energy") -> tuple:
    """The factors of `surface_correction` on the whole cloud, over the bonds the solver makes (the
    partial-volume rule's cutoff and ν; bonds across a pre-crack count for g but hold no energy), and
    LPS's corrected q per node (None: q is unchanged, as with both methods today, since LPS scales
    κ, α and m by the same ḡ_i). energy: the direction factors (n × 3); volume: (V_i per node, V0). Holds every bond in memory: a correction asked for on a large cloud
    costs here what it costs the solver's set-up."""
    points, volume = np.asarray(cloud.points, dtype=np.float64), np.asarray(cloud.volume)
    tree = tree if tree is not None else cKDTree(points)
    horizon, dx = float(resolved["horizon"]), float(resolved["grid_spacing"])
    extension, shell = PARTIAL_VOLUME[resolved["partial_volume"]]
    cutoff = horizon + extension * dx if extension else horizon
    pairs = tree.sparse_distance_matrix(tree, cutoff * BOND_SLACK, output_type="coo_matrix")
    keep = pairs.data > 0
    i, j, dist = pairs.row[keep].astype(np.int64), pairs.col[keep].astype(np.int64), pairs.data[keep]
    nu = np.clip((horizon + 0.5 * dx - dist) * (1.0 / dx), 0.0, 1.0) if shell else 1.0
    intact = ~crosses_cracks(points, i, j, resolved.get("cracks") or [])
    dims = 3 if case["analysis"] == "3d" else 2
    n, weight = len(points), volume[j] * nu
    if method == "volume":
        family = np.bincount(i, weights=weight * intact, minlength=n)
        bulk = math.pi * horizon * horizon * case["thickness"] if dims == 2 else 4.0 / 3.0 * math.pi * horizon ** 3
        return (family, bulk), None
    if law["model"] == "lps":
        law = dict(law, influence=influence(law["kind"], dist, horizon))
    return surface_correction.direction_factors(law, n, dims, horizon, case["thickness"], block - 1, i, j, dist,
                                                (points[j] - points[i]) / dist[:, None], weight, intact), None


def _orientation(o, a, b):
    """Twice the signed area of the triangle o, a, b (core/cracks.cpp orientation), per row."""
    return (a[..., 0] - o[..., 0]) * (b[..., 1] - o[..., 1]) - (a[..., 1] - o[..., 1]) * (b[..., 0] - o[..., 0])


def crosses_cracks(points: np.ndarray, i: np.ndarray, j: np.ndarray, cracks: list) -> np.ndarray:
    """Per bond i→j: does its reference segment properly cross a pre-crack segment in the xy plane?
    The solver's test (core/cracks.cpp segments_cross), with the lower-index end first as it does,
    so that both copies of a bond and the solver agree bitwise."""
    out = np.zeros(len(i), dtype=bool)
    if not cracks or len(i) == 0:
        return out
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    p, q = points[lo, :2], points[hi, :2]
    for crack in cracks:
        a = np.broadcast_to(np.asarray(crack["from"][:2], dtype=np.float64), p.shape)
        b = np.broadcast_to(np.asarray(crack["to"][:2], dtype=np.float64), p.shape)
        ab_p, ab_q = _orientation(a, b, p), _orientation(a, b, q)
        pq_a, pq_b = _orientation(p, q, a), _orientation(p, q, b)
        out |= (((ab_p > 0) & (ab_q < 0)) | ((ab_p < 0) & (ab_q > 0))) & \
               (((pq_a > 0) & (pq_b < 0)) | ((pq_a < 0) & (pq_b > 0)))
    return out


def lps_node_terms(cloud, block: np.ndarray, moduli: list, analysis: str, horizon: float, kind: str,
                   resolved: dict, tree: cKDTree | None = None, chunk: int = SAMPLE) -> np.ndarray:
    """q_i = (d²κ_i + α_i)/m_i per node, m_i = Σ_j ω|ξ|²ν V_j over the whole family (α = 15μ in 3D,
    8μ in 2D), in chunks of nodes. Bonds crossing a pre-crack (case.json `cracks`) are left out of
    m_i, as LpsModel computes m on the bonds intact at the start (core/cracks.cpp cuts them first):
    a node beside a notch has a smaller m, a larger q and so a shorter step."""
    points, volume = np.asarray(cloud.points), np.asarray(cloud.volume)
    tree = tree if tree is not None else cKDTree(points)
    dx = float(resolved["grid_spacing"])
    extension, shell = PARTIAL_VOLUME[resolved["partial_volume"]]
    cutoff = horizon + extension * dx if extension else horizon
    m = np.zeros(len(points))
    for start in range(0, len(points), chunk):
        rows = np.arange(start, min(start + chunk, len(points)))
        pairs = cKDTree(points[rows]).sparse_distance_matrix(tree, cutoff * BOND_SLACK, output_type="coo_matrix")
        keep = pairs.data > 0
        r, cols, dist = pairs.row[keep], pairs.col[keep], pairs.data[keep]
        nu = np.clip((horizon + 0.5 * dx - dist) * (1.0 / dx), 0.0, 1.0) if shell else 1.0
        intact = ~crosses_cracks(points, rows[r], cols, resolved.get("cracks") or [])
        m[rows] += np.bincount(r, weights=influence(kind, dist, horizon) * dist * dist * nu * volume[cols] * intact,
                               minlength=len(rows))
    d = 3 if analysis == "3d" else 2
    per_block = np.array([d * d * k + (15.0 if d == 3 else 8.0) * mu for k, mu in moduli])
    numerator = per_block[block - 1]
    return np.divide(numerator, m, out=np.zeros_like(m), where=m > 0)


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


def check_discretized_case(case: dict, resolved: dict, cloud) -> list[str]:
    """Raise CaseError for a case that cannot run sensibly; return warnings (strings) otherwise.

    case: the validated case (pipeline.case.load_case); resolved: its case.json dictionary
    (pipeline.resolve); cloud: the NodeCloud it was resolved against.
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

    dt_stable, node = case_stable_time_step(case, resolved, cloud, tree)
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
