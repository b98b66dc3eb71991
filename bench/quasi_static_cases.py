"""Quasi-static tension with fracture on the project's own cases (issue 13, `make bench-accuracy`):
cases/traction and cases/plate_with_hole, from their `mixed.yaml`.

For each case: velocity Verlet at loading rates halved from the explicit case's speed, with a light
reference damping (ζ = 0.1 of critical in the body's first axial mode, α = 2ζπc/L) until halving the
rate changes the peak force by < 0.5 % (the slower run is the reference); Verlet at the same rates
undamped and at the case's own damping level (ζ = 0.25); `quasi_static` and `mixed` as
mixed.yaml sets them (its speed, load steps and switching thresholds, no damping). Measured on
every run: the peak force (bench/tension.py's `peak`), the grip displacement at it, the
force–displacement curve up to the reference's peak (relative L2), the crack position (the centroid
along the load of the damaged nodes in each half of the body, so that traction's two symmetric
cracks are both compared), wall and CPU time, force evaluations and evaluation equivalents
(factorisations and solves counted by their measured time).

Resolution: the lattice is `--coarsen` times coarser than the case file's (default 4: dx = 1 mm,
some 1900 and 4900 nodes), so that `make bench-accuracy` stays within about 30 minutes;
`--coarsen 1` is the case's own resolution. A coarser lattice has a smaller critical stretch
(s0 ∝ δ^(−½)), so the grips' end displacement is scaled by 1.2·coarsen^(−½) (1 at full resolution):
every run ends about as far past its peak as mixed.yaml's does (`--end-scale` to set it; --quick,
dx × 8, uses 0.6: there the peak comes later than that rule says).

The speedup line: mixed against the cheapest explicit run as accurate (peak within 2 % of the
reference's, the same crack position), rerun in pairs side by side (mixed, explicit, mixed,
explicit, ...; the fastest of each counts) so that the ratio is measured in one sitting.

`--reuse-explicit DIR` / `--explicit-from DIR`: the explicit rows of an earlier run's --out folder,
when their inputs are byte-identical (bench/explicit_reuse.py says when exactly); mixed,
quasi_static and the paired reruns run here always.
"""
from __future__ import annotations

import copy
import csv
import json
import math
import os
import resource
import sys

import numpy as np

from bench import tension
from bench.explicit_reuse import ExplicitSource
from bench.solver_runs import run_once, stable_dt
from common.paths import REPOSITORY as ROOT

# The explicit case's grip speed (traction.yaml, plate_with_hole.yaml): the first rate tried.
CASES = {"traction": {"explicit_speed": 0.5}, "plate_with_hole": {"explicit_speed": 0.25}}
REFERENCE_ZETA = 0.1          # the reference's damping, fraction of critical in the first axial mode
CASE_ZETA = 0.25              # about the explicit cases' α = 2·10⁴ 1/s
PEAK_CONVERGED = 5e-3         # halving the rate changes the peak by less than this: the reference
PEAK_TOLERANCE = 0.02         # "as accurate as mixed": peak within 2 % of the reference's ...
CRACK_TOLERANCE_DX = 2.0      # ... and each half's crack within 2 dx of the reference's
DAMAGED = 0.3                 # a node belongs to a crack from this damage on
RAMP_FRACTION = 0.2           # explicit runs: the grip speed ramps up over this fraction of the run


# ---------------------------------------------------------------- preparing the lattice and cases
def prepare(name: str, coarsen: float, directory: str, end_scale: float) -> dict:
    """Mesh cases/<name>/<name>.geo, build the lattice of mixed.yaml at coarsen × its dx (node-set
    layers thinner than 5 dx, i.e. a horizon deep, scaled alike) and resolve the case. Returns the
    resolved case (as the solver reads it) with nodes.vtu written next to it in `directory`."""
    from pipeline.case import load_case
    from pipeline.resolve import resolve
    from preprocess import build_node_cloud
    from preprocess.gmsh_mesh import mesh_geo
    from preprocess.node_file import write_node_file

    case = load_case(os.path.join(ROOT, "cases", name, "mixed.yaml"))
    dx = case["discretization"]["dx"]
    case["discretization"]["dx"] = dx * coarsen
    layers = {}
    for set_name, opts in case["node_sets"].items():
        if opts["layer"] is not None:
            opts["layer"] = opts["layer"] * coarsen if opts["layer"] < 5 * dx else opts["layer"]
            layers[set_name] = opts["layer"]
    os.makedirs(directory, exist_ok=True)
    mesh = os.path.join(directory, "mesh.msh")
    mesh_geo(os.path.join(ROOT, "cases", name, f"{name}.geo"), mesh, case["dimension"], case["geometry"]["parameters"])
    disc = case["discretization"]
    cloud = build_node_cloud(mesh, dimension=case["dimension"], thickness=case["thickness"], method=disc["method"],
                             dx=disc["dx"], block_names=list(case["materials"]), set_layers=layers,
                             lattice_origin=disc["origin"])
    resolved = resolve(case, node_sets=list(cloud.sets), grid_spacing=float(cloud.grid_spacing),
                       nodes_file="../nodes.vtu")
    write_node_file(os.path.join(directory, "nodes.vtu"), cloud)
    x = cloud.points[:, 0]
    resolved["_nodes"] = len(cloud.volume)
    resolved["_middle"] = float(0.5 * (x.min() + x.max()))
    resolved["_length"] = float(x.max() - x.min())
    resolved["_end_scale"] = end_scale
    return resolved


def axial_alpha(base: dict, zeta: float) -> float:
    """α = 2ζω₁, ω₁ = πc/L the first axial mode of the free body (c = √(E/ρ), L its length)."""
    block = base["blocks"][0]
    omega = math.pi * math.sqrt(block["youngs_modulus"] / block["density"]) / base["_length"]
    return float(f"{2.0 * zeta * omega:.3g}")


def grip_tables(base: dict) -> tuple[list, list, float]:
    """(times, values of the right grip's x displacement, end time) of mixed.yaml, scaled by the
    end-displacement factor (times and values alike: the speed is the file's)."""
    table = next(c for c in base["boundary_conditions"] if c["set"] == "right" and c["component"] == 0)
    k = base["_end_scale"]
    return [t * k for t in table["times"]], [v * k for v in table["values"]], base["time"]["end"] * k


def end_displacement(base: dict) -> float:
    times, values, end = grip_tables(base)
    return float(np.interp(end, times, values))


def solver_case(base: dict, integrator: str, end: float, conditions: list, damping: float,
                history_every: int) -> dict:
    """The resolved case with its integrator, end, conditions and damping replaced; one frame (the
    last: the crack) and a history row every `history_every` steps."""
    case = {k: copy.deepcopy(v) for k, v in base.items() if not k.startswith("_")}
    case["time"].update(integrator=integrator, end=end, dt="stable", safety_factor=0.8)
    case["boundary_conditions"] = conditions
    case["damping"] = damping
    case["output"].update(every_time=end, every_steps=None, history_every=history_every)
    return case


def explicit_case(base: dict, speed: float, damping: float, history_every: int) -> dict:
    """Verlet, each grip's x velocity ramped to `speed` over the first fifth of the run, y held;
    the run ends when each grip has moved the scaled end displacement."""
    end = explicit_end(base, speed)
    ramp = [0.0, RAMP_FRACTION * end]
    conditions = []
    for grip, sign in (("left", -1.0), ("right", 1.0)):
        conditions += [{"set": grip, "kind": "velocity", "component": 0, "times": ramp, "values": [0.0, sign * speed]},
                       {"set": grip, "kind": "displacement", "component": 1, "times": [0.0], "values": [0.0]}]
    return solver_case(base, "verlet", end, conditions, damping, history_every)


def explicit_end(base: dict, speed: float) -> float:
    return end_displacement(base) / (speed * (1.0 - RAMP_FRACTION / 2.0))


def implicit_case(base: dict, integrator: str) -> dict:
    """quasi_static or mixed as mixed.yaml sets them (tables scaled to the end displacement)."""
    times, values, end = grip_tables(base)
    conditions = []
    for c in base["boundary_conditions"]:
        c = copy.deepcopy(c)
        if c["component"] == 0 and c["kind"] == "displacement":
            sign = 1.0 if c["set"] == "right" else -1.0
            c["times"], c["values"] = list(times), [sign * v for v in values]
        conditions.append(c)
    return solver_case(base, integrator, end, conditions, 0.0, 1)


def write(directory: str, run_name: str, case: dict) -> str:
    run_dir = os.path.join(directory, run_name)
    os.makedirs(run_dir, exist_ok=True)
    case = dict(case, case=run_name, output_dir=".")
    path = os.path.join(run_dir, "case.json")
    with open(path, "w", encoding="utf-8") as stream:
        json.dump(case, stream, indent=1)
    return path


# ---------------------------------------------------------------- measures
def grip_displacement(case: dict, t: np.ndarray) -> np.ndarray:
    """The right grip's prescribed x displacement at times t (a displacement table, or the
    integral of a velocity table ramped linearly then constant)."""
    c = next(c for c in case["boundary_conditions"] if c["set"] == "right" and c["component"] == 0)
    if c["kind"] == "displacement":
        return np.interp(t, c["times"], c["values"])
    ramp, speed = c["times"][1], c["values"][1]
    return np.where(t < ramp, speed * t * t / (2.0 * ramp), speed * (t - ramp / 2.0))


def history(run_dir: str) -> dict[str, np.ndarray]:
    with open(os.path.join(run_dir, "history.csv"), newline="", encoding="utf-8") as stream:
        rows = list(csv.DictReader(stream))
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def crack_positions(x: np.ndarray, damage: np.ndarray, middle: float) -> tuple[float, float]:
    """(left, right): the mean x of the nodes with damage ≥ 0.3 in each half of the body (x below
    and above `middle`), NaN for a half without any. Traction breaks in two cracks symmetric about
    the middle, plate_with_hole in two running up and down from the hole: each half's centroid
    places its own crack (a crack on the middle line shows in both halves alike)."""
    damaged = damage >= DAMAGED
    out = []
    for half in (x < middle, x >= middle):
        pick = damaged & half
        out.append(float(np.mean(x[pick])) if np.any(pick) else float("nan"))
    return out[0], out[1]


def same_crack(got: tuple[float, float], reference: tuple[float, float], tolerance: float) -> bool:
    """Each half cracked (or not) as in the reference, and where cracked within `tolerance` of it."""
    for a, b in zip(got, reference):
        if math.isnan(a) != math.isnan(b):
            return False
        if not math.isnan(a) and abs(a - b) > tolerance:
            return False
    return True


def measures(run_dir: str, case: dict, middle: float, reference: dict | None = None) -> dict:
    from postprocess.series import read_frame, read_series

    h = history(run_dir)
    d, f = grip_displacement(case, h["time"]), h["reaction_right_fx"]
    peak_force, peak_displacement, _ = tension.peak(d, f)
    frames = read_series(os.path.join(run_dir, "frames.pvd"))
    frame = read_frame(os.path.join(run_dir, frames[-1][1]))
    cracks = crack_positions(frame.points[:, 0], frame.damage, middle)
    out = {"peak_force": peak_force, "peak_displacement": peak_displacement, "cracks": cracks, "curve": (d, f),
           "history": h}
    if reference is not None:
        out["curve_error"] = tension.curve_error(d, f, *reference["curve"])
        out["peak_error"] = abs(peak_force - reference["peak_force"]) / reference["peak_force"]
        out["same_crack"] = same_crack(cracks, reference["cracks"], CRACK_TOLERANCE_DX * case["grid_spacing"])
    return out


def where_time_goes(h: dict[str, np.ndarray]) -> dict:
    """From a mixed or quasi_static history (a row every step): static load steps (mode 1), their
    Newton iterations, explicit steps (mode 0), implicit steps (mode 2, mixed.start: implicit), and
    the solver wall time of the static and explicit steps."""
    mode = h.get("mode", np.zeros_like(h["time"]))
    wall = np.diff(h["wall_time"], prepend=0.0)
    step = h["step"] > 0
    static, explicit, implicit = step & (mode == 1), step & (mode == 0), step & (mode == 2)
    return {"static_steps": int(np.sum(static)), "newton_iterations": int(np.sum(h["iterations"][static])),
            "explicit_steps": int(np.sum(explicit)), "implicit_steps": int(np.sum(implicit)),
            "static_wall": float(np.sum(wall[static])), "explicit_wall": float(np.sum(wall[explicit]))}


# ---------------------------------------------------------------- choosing, and the speedup line
def reference_search(peaks: list[float]) -> int | None:
    """Index of the reference in a family of peaks at halved rates: the first run whose peak is
    within 0.5 % of the previous (faster) one's; None while no halving has converged."""
    for k in range(1, len(peaks)):
        if abs(peaks[k] - peaks[k - 1]) / abs(peaks[k]) < PEAK_CONVERGED:
            return k
    return None


def rival(rows: list[dict], problem: str) -> dict | None:
    """The cheapest explicit row as accurate as asked (peak within 2 % of the reference's, the same
    crack position). Cheapest by CPU time (user + system of the solver process, 1 thread: its wall
    time on a quiet machine), which the load of a shared machine barely moves, where it makes the
    wall time of one run several times longer at random; the line then gives paired wall times."""
    accurate = [r for r in rows if r["problem"] == problem and r["scheme"].startswith("verlet")
                and r["status"] == "ok" and r["peak_error"] <= PEAK_TOLERANCE and r["same_crack"]]
    return min(accurate, key=lambda r: r["cpu_time"]) if accurate else None


def speedup_line(problem: str, mixed_wall: float, explicit: dict | None, explicit_wall: float,
                 peak_error: float, mixed_same_crack: bool = True) -> str:
    """`speedup <problem>: mixed <s> s against explicit <s> s (<scheme, parameter>): <ratio>x,
    peak force <rel. error>` (the ratio explicit / mixed: above 1 mixed is faster), with
    `, crack elsewhere` appended when mixed's own crack is not the reference's."""
    crack = "" if mixed_same_crack else ", crack elsewhere"
    if explicit is None:
        return (f"speedup {problem}: mixed {mixed_wall:.3f} s against no explicit run as accurate, "
                f"peak force {peak_error:.2e}{crack}")
    return (f"speedup {problem}: mixed {mixed_wall:.3f} s against explicit {explicit_wall:.3f} s "
            f"({explicit['scheme']}, {explicit['parameter']:g} m/s): {explicit_wall / mixed_wall:.3g}x, "
            f"peak force {peak_error:.2e}{crack}")


# ---------------------------------------------------------------- running
def timed_run(solver: str, case_path: str, threads: int) -> dict:
    """solver_runs.run_once, plus the CPU time (user + system) of the solver process, which
    the load of a shared machine disturbs less than the wall time."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = run_once(solver, case_path, threads)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    r["cpu"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return r


def runs(args, rows: list[dict], name: str) -> str:
    """Every run of one case; appends its rows and returns its speedup line."""
    directory = os.path.join(args.out, name)
    base = prepare(name, args.coarsen, directory, args.end_scale)
    middle = base["_middle"]
    print(f"{name}: dx = {base['grid_spacing'] * 1e3:g} mm ({args.coarsen:g} × the case's), {base['_nodes']} nodes; "
          f"each grip to {end_displacement(base) * 1e3:.4g} mm", flush=True)
    ref_alpha = axial_alpha(base, REFERENCE_ZETA)
    speed0 = CASES[name]["explicit_speed"]
    dt_guess = [None]
    source = ExplicitSource(args.reuse_explicit or args.explicit_from,
                            "reuse" if args.reuse_explicit else "from", args.solver, args.threads)
    print(f"  {name}: {source.describe()}", flush=True)
    notes = {}

    def explicit(speed: float, alpha: float):
        every = 1 if dt_guess[0] is None else max(1, int(explicit_end(base, speed) / dt_guess[0] / 3000))
        case = explicit_case(base, speed, alpha, every)
        path = write(directory, f"verlet-alpha{alpha:g}-v{speed:g}", case)
        r, run_dir, notes[run_dir] = source.run(name, path, timed_run)
        if notes[run_dir]:
            print(f"    {os.path.basename(run_dir)}: {notes[run_dir]}", flush=True)
        if r["status"] == "ok" and dt_guess[0] is None:
            dt_guess[0] = 0.8 * stable_dt(r["log"])
        return case, run_dir, r

    family = []
    speed = speed0
    for _ in range(args.halvings + 1):
        case, run_dir, r = explicit(speed, ref_alpha)
        if r["status"] != "ok":
            raise SystemExit(f"{name}: the explicit run at {speed:g} m/s failed: {r['status']}")
        m = measures(run_dir, case, middle)
        family.append((speed, case, run_dir, r, m))
        print(f"  {name}: Verlet α = {ref_alpha:g} 1/s at {speed:g} m/s: peak {m['peak_force']:.5g} N at "
              f"{m['peak_displacement'] * 1e3:.4g} mm, {r['steps']} steps, {r['wall']:.2f} s", flush=True)
        if reference_search([f[4]["peak_force"] for f in family]) is not None:
            break
        speed /= 2.0
    found = reference_search([f[4]["peak_force"] for f in family])
    ref_speed, _, ref_dir, ref_run, reference = family[-1]
    per_evaluation = ref_run["wall"] / ref_run["evaluations"]
    print(f"{name}: reference = Verlet, α = {ref_alpha:g} 1/s, at {ref_speed:g} m/s "
          f"({'converged' if found is not None else 'NOT converged: the halvings ran out'}); peak "
          f"{reference['peak_force']:.5g} N at {reference['peak_displacement'] * 1e3:.4g} mm, cracks at x = "
          f"{', '.join(f'{c * 1e3:.3g}' for c in reference['cracks'])} mm", flush=True)

    def row(scheme, parameter, case, run_dir, r) -> dict:
        ok = r["status"] == "ok"
        m = measures(run_dir, case, middle, reference) if ok else {}
        factorisations, factor_s, solves, solve_s = tension.linear_algebra(r["log"])
        out = {"problem": name, "scheme": scheme, "parameter": parameter, "wall_time": r["wall"], "cpu_time": r["cpu"],
               "force_evaluations": r["evaluations"], "steps": r["steps"],
               "mean_dt": case["time"]["end"] / r["steps"] if r["steps"] else float("nan"),
               "error": m.get("peak_error", float("nan")), "broken_bonds": r["broken_bonds"], "status": r["status"],
               "evaluation_equivalents": r["evaluations"] + (factor_s + solve_s) / per_evaluation,
               "factorisations": factorisations, "factorisation_time": factor_s, "solves": solves,
               "solve_time": solve_s, "peak_force": m.get("peak_force", float("nan")),
               "peak_displacement": m.get("peak_displacement", float("nan")),
               "curve_error": m.get("curve_error", float("nan")), "peak_error": m.get("peak_error", float("nan")),
               "crack_left": m.get("cracks", (float("nan"),) * 2)[0],
               "crack_right": m.get("cracks", (float("nan"),) * 2)[1],
               "same_crack": m.get("same_crack", False), "reference": run_dir == ref_dir,
               "nodes": base["_nodes"], "grid_spacing": base["grid_spacing"], "run_dir": run_dir,
               "case_path": os.path.join(directory, os.path.basename(run_dir), "case.json"),
               "explicit_source": notes.get(run_dir, "")}
        if ok and scheme in ("mixed", "quasi_static"):
            out.update(where_time_goes(m["history"]))
        print(f"  {scheme:18s} {parameter:<8g} {r['status'][:6]:6s} steps {r['steps']:7d} evals {r['evaluations']:7d} "
              f"equiv {out['evaluation_equivalents']:9.0f} wall {r['wall']:7.2f} s cpu {r['cpu']:7.2f} s peak "
              f"{out['peak_force']:.5g} N ({out['peak_error']:.2%}) at {out['peak_displacement'] * 1e3:.4g} mm curve "
              f"{out['curve_error']:.2e} cracks {out['crack_left'] * 1e3:.3g}, {out['crack_right'] * 1e3:.3g} mm "
              f"{'same' if out['same_crack'] else 'other'}", flush=True)
        return out

    mine = []
    for speed, case, run_dir, r, _ in family:
        mine.append(row(f"verlet-alpha{ref_alpha:g}", speed, case, run_dir, r))
    for zeta in args.zetas:
        alpha = axial_alpha(base, zeta)
        if alpha == ref_alpha:
            continue
        for speed, *_ in family:
            case, run_dir, r = explicit(speed, alpha)
            mine.append(row(f"verlet-alpha{alpha:g}", speed, case, run_dir, r))
    if args.explicit_only:
        rows.extend(mine)
        if source.summary():
            print(f"  {name}: {source.summary()}", flush=True)
        return f"{name}: explicit rows only (--explicit-only): no mixed run, no speedup"
    cases = {}
    for scheme in ("quasi_static", "mixed"):
        case = implicit_case(base, scheme)
        path = write(directory, scheme, case)
        cases[scheme] = path
        mine.append(row(scheme, 0.0 if scheme == "quasi_static" else grip_tables(base)[1][-1] / grip_tables(base)[0][-1],
                        case, os.path.dirname(path), timed_run(args.solver, path, args.threads)))
    rows.extend(mine)
    if source.summary():
        print(f"  {name}: {source.summary()}", flush=True)
    mixed = next(r for r in mine if r["scheme"] == "mixed")
    if mixed["status"] != "ok":
        return f"speedup {name}: mixed failed ({mixed['status']})"
    best = rival(mine, name)
    mixed_wall, explicit_wall = mixed["wall_time"], best["wall_time"] if best else float("nan")
    if best is not None and args.pairs > 0:
        # Side by side: mixed and its rival alternately, the fastest of each.
        rival_path = best["case_path"]   # in this run's folder, also when its row was reused
        def walls(group):
            return ", ".join(f"{r['wall']:.2f}" for r in group)

        mixed_runs, rival_runs = [], []
        for _ in range(args.pairs):
            mixed_runs.append(timed_run(args.solver, cases["mixed"], args.threads))
            rival_runs.append(timed_run(args.solver, rival_path, args.threads))
        mixed_wall, explicit_wall = min(r["wall"] for r in mixed_runs), min(r["wall"] for r in rival_runs)
        mixed_cpu, explicit_cpu = min(r["cpu"] for r in mixed_runs), min(r["cpu"] for r in rival_runs)
        print(f"  {name}: paired reruns, mixed {walls(mixed_runs)} s wall; "
              f"{best['scheme']} at {best['parameter']:g} m/s {walls(rival_runs)} s "
              f"wall; by CPU time (user + system) {mixed_cpu:.2f} s against {explicit_cpu:.2f} s: "
              f"{explicit_cpu / mixed_cpu:.3g}x", flush=True)
    return speedup_line(name, mixed_wall, best, explicit_wall, mixed["peak_error"], mixed["same_crack"])


def add_arguments(parser) -> None:
    parser.add_argument("--coarsen", type=float, default=None,
                        help="traction, plate_with_hole: lattice spacing as a multiple of the case's dx (default 4; "
                             "--quick 8; 1 = the case's own resolution)")
    parser.add_argument("--full-resolution", action="store_true", help="traction, plate_with_hole at the case's dx")
    parser.add_argument("--halvings", type=int, default=None,
                        help="traction, plate_with_hole: most halvings of the loading rate in the reference search "
                             "(default 7, --quick 3)")
    parser.add_argument("--end-scale", type=float, default=None,
                        help="traction, plate_with_hole: the grips' end displacement as a multiple of mixed.yaml's "
                             "(default 1.2/sqrt(coarsen), 1 at full resolution; --quick 0.6: at dx × 8 the peak comes "
                             "later than s0 ∝ δ^(-1/2) says, and 1.2/sqrt(8) ended the plate's runs at its peak)")
    parser.add_argument("--pairs", type=int, default=None,
                        help="paired reruns of mixed and its explicit rival (default 2, --quick 1)")
    parser.add_argument("--explicit-only", action="store_true",
                        help="traction, plate_with_hole: the explicit rows alone (no quasi_static, mixed or speedup): "
                             "a folder for a later --reuse-explicit / --explicit-from")
    reuse = parser.add_mutually_exclusive_group()
    reuse.add_argument("--reuse-explicit", metavar="DIR", default=None,
                       help="traction, plate_with_hole: take each explicit run from DIR (an earlier --out) when its "
                            "case.json and nodes.vtu are byte-identical and the same solver file (SHA-256) made it "
                            "on as many threads; mixed, quasi_static and the paired reruns run here")
    reuse.add_argument("--explicit-from", metavar="DIR", default=None,
                       help="traction, plate_with_hole: take the explicit runs of DIR (an earlier --out) whose inputs "
                            "are byte-identical, whatever solver made them; the first of each problem is rerun and "
                            "its results compared (any difference stops the benchmark); their times are DIR's")


def settle_arguments(args) -> None:
    """Defaults that depend on --quick and --full-resolution."""
    if args.full_resolution:
        args.coarsen = 1.0
    if args.coarsen is None:
        args.coarsen = 8.0 if args.quick else 4.0
    if args.coarsen <= 0:
        sys.exit("--coarsen must be positive")
    if args.end_scale is None:
        args.end_scale = 0.6 if args.quick else (1.0 if args.coarsen == 1 else 1.2 / math.sqrt(args.coarsen))
    args.halvings = (3 if args.quick else 7) if args.halvings is None else args.halvings
    args.pairs = (1 if args.quick else 2) if args.pairs is None else args.pairs
    args.zetas = (0.0,) if args.quick else (0.0, CASE_ZETA)
    for option, value in (("--reuse-explicit", args.reuse_explicit), ("--explicit-from", args.explicit_from)):
        if value is None:
            continue
        if not os.path.isdir(value):
            sys.exit(f"{option} {value}: no such folder (give the --out folder of an earlier run)")
        if os.path.realpath(value) == os.path.realpath(args.out):
            # This run rewrites case.json and nodes.vtu before comparing them with DIR's.
            sys.exit(f"{option} {value}: the same folder as --out; write this run elsewhere")
