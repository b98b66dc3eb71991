"""Run time against error (make bench-accuracy): Verlet at several safety factors of eq. 2.5 and at
the exact limit, and the adaptive step of thesis §2.2 over a sweep of TOL for φ = 1 and φ = ½ (at the
default Δt_max = eq. 2.5, and for φ = ½ also with Δt_max = 4 × eq. 2.5, so that the controller alone
sets the step), on an elastic wave in a strip and on a plate with a hole pulled to fracture; each
against a Verlet run at 1/16 of the default step, 0.05 × eq. 2.5 (docs/theory.md T18). A benchmark,
not a test: it asserts nothing. docs/accuracy.md reads the numbers.

Errors: the wave, the relative L2 norm of the displacement over the 11 saved frames,
sqrt(Σ_frames Σ_nodes |u − u_ref|² / Σ_frames Σ_nodes |u_ref|²); the fracture, the relative L2 norm
of the difference of the final damage fields. Cost: the solver's own time-loop wall time (run.log's
`done:` line, frame output included, set-up excluded), the minimum over --repeat runs of any run
shorter than 2 s (docs/theory.md T18: the minimum of repeated runs), and the force evaluations
(rejected adaptive attempts included), which do not depend on the machine.

A third problem, quasi-static tension with fracture (bench/tension.py, issue 13): a notched strip
pulled by its grips, Verlet at several grip speeds and damping values, quasi_static and mixed,
against the explicit run whose loading rate has converged (found here by halving the speed); the
error is that of the peak force, the csv rows add the displacement at the peak, the curve up to it,
the crack's position and the cost in force-evaluation equivalents. The same on the project's
cases traction and plate_with_hole (bench/quasi_static_cases.py: their mixed.yaml, on a lattice
--coarsen times coarser than the case's, 4 by default). The output ends with one
`speedup <problem>: ...` line per problem that has a mixed row.

Writes out/bench/accuracy.csv (a row per run) and out/bench/accuracy.png (log-log error against
wall time and against force evaluations).

    /usr/bin/python3 -m bench.accuracy [--solver build/solver/pdsolve] [--threads 1] [--repeat 3] [--quick]
                                       [--problems wave,fracture,tension,traction,plate_with_hole]
                                       [--coarsen 4 | --full-resolution] [--halvings 7] [--pairs 2]
                                       [--reuse-explicit DIR | --explicit-from DIR] [--explicit-only]
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import sys

import numpy as np

from bench import quasi_static_cases, tension
from bench.solver_runs import machine, run, stable_dt
from common.output_lock import exit_code, output_lock
from common.paths import REPOSITORY as ROOT, pdsolve
from postprocess.series import read_frame, read_series
from preprocess.cloud import NodeCloud
from preprocess.node_file import write_node_file

DX = 1.0e-3
PROBLEMS = ("wave", "fracture", "tension", "traction", "plate_with_hole")


def strip_problem(directory: str) -> dict:
    """An elastic wave: a 120 × 24 strip (2880 nodes), the left grip moved by a smooth velocity pulse
    (a Hann pulse of 2 m/s peak over 8 µs as an 11-point table), the wave runs along the strip;
    11 frames over 20 µs."""
    nx, ny = 120, 24
    x, y = np.meshgrid(np.arange(nx) * DX, np.arange(ny) * DX, indexing="xy")
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    grip = points[:, 0] < 2.5 * DX
    cloud = NodeCloud(points=points, volume=np.full(len(points), DX * DX * 1e-3), block=np.ones(len(points), np.int32),
                      sets={"grip": grip}, grid_spacing=DX, dimension=2)
    write_node_file(os.path.join(directory, "nodes.vtu"), cloud)
    times = np.linspace(0.0, 8e-6, 11)
    pulse = 2.0 * np.sin(np.pi * times / 8e-6) ** 2  # m/s
    return {
        "dimension": 2, "analysis": "plane_stress", "thickness": 1e-3, "grid_spacing": DX, "horizon": 3.015 * DX,
        "blocks": [{"id": 1, "name": "glass", "model": "pmb", "density": 2440.0, "youngs_modulus": 7.2e10,
                    "fracture_energy": None}],
        "node_sets": ["grip"],
        "boundary_conditions": [{"set": "grip", "kind": "velocity", "component": 0, "times": times.tolist(),
                                 "values": pulse.tolist()}],
        "end": 2e-5, "every_time": 2e-6, "measure": "displacement",
    }


def hole_problem(directory: str) -> dict:
    """Fracture: an 80 × 40 plate with a hole of radius 6 dx (PMMA, s0 = 6.6·10⁻³), both ends pulled
    apart at 4 m/s after a 5 µs ramp. Each end sends in a tensile wave of strain v/c = 2.4·10⁻³; where
    the two meet (4.9·10⁻³, still below s0) the hole concentrates it about threefold, and two cracks run
    from the hole's edge across the plate, perpendicular to the load, within the 60 µs run. The error
    is measured on the final damage field."""
    nx, ny = 80, 40
    x, y = np.meshgrid(np.arange(nx) * DX, np.arange(ny) * DX, indexing="xy")
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    centre = np.array([(nx - 1) * DX / 2, (ny - 1) * DX / 2])
    keep = np.hypot(points[:, 0] - centre[0], points[:, 1] - centre[1]) > 6 * DX
    points = points[keep]
    left, right = points[:, 0] < 2.5 * DX, points[:, 0] > (nx - 3.5) * DX
    cloud = NodeCloud(points=points, volume=np.full(len(points), DX * DX * 1e-3), block=np.ones(len(points), np.int32),
                      sets={"left": left, "right": right}, grid_spacing=DX, dimension=2)
    write_node_file(os.path.join(directory, "nodes.vtu"), cloud)
    ramp = [0.0, 5e-6]
    return {
        "dimension": 2, "analysis": "plane_stress", "thickness": 1e-3, "grid_spacing": DX, "horizon": 3.015 * DX,
        "blocks": [{"id": 1, "name": "pmma", "model": "pmb", "density": 1190.0, "youngs_modulus": 3.2e9,
                    "fracture_energy": 300.0}],
        "node_sets": ["left", "right"], "no_fail_sets": ["left", "right"],
        "boundary_conditions": [
            {"set": "left", "kind": "velocity", "component": 0, "times": ramp, "values": [0.0, -4.0]},
            {"set": "right", "kind": "velocity", "component": 0, "times": ramp, "values": [0.0, 4.0]}],
        "end": 6e-5, "every_time": 6e-5, "measure": "damage",
    }


def write_case(directory: str, problem: dict, name: str, time: dict, adaptive: dict | None,
               sections: dict | None = None, history_every: int = 1_000_000) -> str:
    """case.json of one run in directory/name/. `sections`: further case sections as they are
    (quasi_static, mixed); the problem's cracks, damping and reactions go in when it has them."""
    run_dir = os.path.join(directory, name)
    os.makedirs(run_dir, exist_ok=True)
    case = {key: problem[key] for key in ("dimension", "analysis", "thickness", "grid_spacing", "horizon", "blocks",
                                          "node_sets", "boundary_conditions")}
    case.update({"format_version": 1, "case": name, "nodes_file": "../nodes.vtu", "output_dir": ".",
                 "no_fail_sets": problem.get("no_fail_sets", []), "initial_conditions": [],
                 "damping": problem.get("damping", 0.0),
                 "time": dict(time, end=problem["end"], max_steps=10_000_000),
                 "output": {"every_time": problem["every_time"], "every_steps": None,
                            "history_every": history_every}})
    if problem.get("cracks"):
        case["cracks"] = problem["cracks"]
    if problem.get("measure") == "tension":
        case["output"]["reactions"] = ["right"]
    if adaptive:
        case["adaptive"] = adaptive
    case.update(sections or {})
    path = os.path.join(run_dir, "case.json")
    with open(path, "w", encoding="utf-8") as stream:
        json.dump(case, stream, indent=1)
    return path


def fields(run_dir: str, measure: str) -> list[np.ndarray]:
    frames = read_series(os.path.join(run_dir, "frames.pvd"))
    out = []
    for _time, path in frames:
        frame = read_frame(os.path.join(run_dir, path))
        out.append(frame.displacement if measure == "displacement" else frame.damage)
    return out if measure == "displacement" else out[-1:]


def error(run_dir: str, reference: list[np.ndarray], measure: str) -> float:
    """Relative L2 over the saved times (displacement) or of the final field (damage)."""
    got = fields(run_dir, measure)
    if len(got) != len(reference):
        return float("nan")
    num = sum(float(np.sum((a - b) ** 2)) for a, b in zip(got, reference))
    den = sum(float(np.sum(b ** 2)) for b in reference)
    return (num / den) ** 0.5


def schemes(quick: bool, dt_stable: float):
    """(scheme, parameter, time section, adaptive section) of every run."""
    factors = [1.0, 0.8, 0.5, 0.25] if quick else [1.0, 0.9, 0.8, 0.5, 0.25, 0.125, 0.025]
    # 0.025: half the reference step, which shows how far the reference itself is from converged.
    for f in factors:
        yield "verlet-eq2.5", f, {"integrator": "verlet", "dt": "stable", "safety_factor": f}, None
    for f in [1.0, 0.95] if quick else [1.0, 0.95, 0.8, 0.5]:
        yield "verlet-exact", f, {"integrator": "verlet", "dt": "exact", "safety_factor": f}, None
    tols = [1e-2, 1e-4] if quick else [1e-2, 1e-3, 1e-4, 1e-5]
    # Every adaptive setting at its default (K_d 20, p 3, first step 0.8 × eq. 2.5, Δt_max = eq. 2.5)
    # but TOL and φ; the "dtmax4" runs lift Δt_max to 4 × eq. 2.5.
    for label, phi, dt_max in (("adaptive-phi1", 1.0, None), ("adaptive-phi0.5", 0.5, None),
                               ("adaptive-phi0.5-dtmax4", 0.5, 4.0 * dt_stable)):
        for tol in tols:
            yield (label, tol, {"integrator": "adaptive", "dt": "stable", "safety_factor": 0.8},
                   {"tol": tol, "kd": 20, "p": 3.0, "phi": phi, "dt_initial": None, "dt_min": None,
                    "dt_max": dt_max})


def tension_runs(args, repeat: int, rows: list[dict]) -> None:
    """The quasi-static tension problem (bench/tension.py): the explicit reference found by halving
    the grip speed, explicit rows at those speeds with and without damping, quasi_static and mixed.
    Appends a row per run to `rows`."""
    directory = os.path.join(args.out, "tension")
    os.makedirs(directory, exist_ok=True)
    base = tension.problem(directory)
    first_speed = 0.8 if not args.quick else 0.4
    halvings = 10 if not args.quick else 1

    def explicit(speed: float, damping: float, history_every: int):
        p = tension.case(base, speed, damping)
        name = f"verlet-alpha{damping:g}-v{speed:g}"
        case_path = write_case(directory, p, name, {"integrator": "verlet", "dt": "stable", "safety_factor": 0.8},
                               None, history_every=history_every)
        r = run(args.solver, case_path, args.threads, repeat)
        return p, os.path.dirname(case_path), r

    def every(speed: float, dt: float) -> int:  # some 4000 history rows a run
        return max(1, int(tension.end_time(speed) / dt / 4000))

    # The reference: Verlet with light damping (ζ = 0.1 of critical in the strip's first axial mode),
    # the speed halved until the peak changes by < 0.5 %. Undamped runs do not settle so: every bond
    # that breaks at the notch before the peak sends out waves that never die down, and the peak
    # moved by 1-2.4 % per halving down to 0.006 m/s (measured;
    # docs/notes/2026-12-02-accuracy-tension.md).
    reference_alpha = float(f"{2.0 * tension.REFERENCE_ZETA * tension.OMEGA_1:.3g}")
    family, dt = [], None
    speed = first_speed
    for _ in range(halvings + 1):
        p, run_dir, r = explicit(speed, reference_alpha, every(speed, dt) if dt else 1)
        if r["status"] != "ok":
            raise SystemExit(f"tension: the explicit run at {speed:g} m/s failed: {r['status']}")
        dt = dt or 0.8 * stable_dt(r["log"])
        m = tension.measures(run_dir, speed, p["end"])
        family.append((speed, p, run_dir, r, m))
        print(f"  tension: Verlet, α = {reference_alpha:g} 1/s, at {speed:g} m/s: peak {m['peak_force']:.4g} N at "
              f"{m['peak_displacement'] * 1e3:.4g} mm, {r['steps']} steps, {r['wall']:.3f} s", flush=True)
        if len(family) >= 2 and abs(m["peak_force"] - family[-2][4]["peak_force"]) / m["peak_force"] < tension.PEAK_CONVERGED:
            break
        speed /= 2.0
    converged = len(family) >= 2 and abs(family[-1][4]["peak_force"] - family[-2][4]["peak_force"]) \
        / family[-1][4]["peak_force"] < tension.PEAK_CONVERGED
    ref_speed, ref_problem, ref_dir, ref_run, reference = family[-1]
    seconds_per_evaluation = ref_run["wall"] / ref_run["evaluations"]
    print(f"tension: reference = Verlet, α = {reference_alpha:g} 1/s, at {ref_speed:g} m/s "
          f"({'converged' if converged else 'NOT converged: the halvings ran out'}); peak {reference['peak_force']:.4g} N "
          f"at {reference['peak_displacement'] * 1e3:.4g} mm, crack at x = {reference['crack_x'] * 1e3:.3g} mm "
          f"({'cut through' if reference['cut'] else 'not cut through'}); {seconds_per_evaluation * 1e3:.3f} ms per "
          f"force evaluation", flush=True)

    def row(scheme: str, parameter: float, r: dict, run_dir: str, speed: float, end: float) -> dict:
        m = tension.measures(run_dir, speed, end, reference) if r["status"] == "ok" else {}
        factorisations, factor_s, solves, solve_s = tension.linear_algebra(r["log"])
        out = {"problem": "tension", "scheme": scheme, "parameter": parameter, "wall_time": r["wall"],
               "force_evaluations": r["evaluations"], "steps": r["steps"],
               "mean_dt": end / r["steps"] if r["steps"] else float("nan"),
               "error": m.get("peak_error", float("nan")), "broken_bonds": r["broken_bonds"], "status": r["status"],
               "evaluation_equivalents": r["evaluations"] + (factor_s + solve_s) / seconds_per_evaluation,
               "factorisations": factorisations, "factorisation_time": factor_s, "solves": solves, "solve_time": solve_s,
               "peak_force": m.get("peak_force", float("nan")),
               "peak_displacement": m.get("peak_displacement", float("nan")),
               "curve_error": m.get("curve_error", float("nan")), "crack_x": m.get("crack_x", float("nan")),
               "cut_through": m.get("cut", False), "same_crack": m.get("same_crack", False),
               "peak_error": m.get("peak_error", float("nan"))}
        out["reference"] = run_dir == ref_dir
        print(f"  {scheme:16s} {parameter:<8g} {r['status'][:6]:6s} steps {r['steps']:7d}  evals {r['evaluations']:7d}  "
              f"equiv {out['evaluation_equivalents']:9.0f}  wall {r['wall']:7.3f} s  peak {out['peak_force']:.4g} N "
              f"({out['peak_error']:.2%})  curve {out['curve_error']:.2e}  crack x {out['crack_x'] * 1e3:.3g} mm "
              f"{'cut' if out['cut_through'] else 'not cut'}", flush=True)
        return out

    for speed, p, run_dir, r, _ in family:
        rows.append(row(f"verlet-alpha{reference_alpha:g}", speed, r, run_dir, speed, p["end"]))
    # The other damping values at the same speeds: none, and ζ = 0.5 of critical (full runs only).
    for zeta in ((0.0, 0.5) if not args.quick else (0.0,)):
        alpha = float(f"{2.0 * zeta * tension.OMEGA_1:.3g}")
        for speed, *_ in family:
            p, run_dir, r = explicit(speed, alpha, every(speed, dt))
            rows.append(row(f"verlet-alpha{alpha:g}", speed, r, run_dir, speed, p["end"]))
    # quasi_static and mixed: load steps of 1/200 of the run (0.55 µm of grip displacement), no
    # damping, the reference's tables (time is physical for mixed, a load parameter for quasi_static).
    steps = {"dt_initial": ref_problem["end"] / 200, "dt_max": ref_problem["end"] / 200}
    for scheme in ("quasi_static", "mixed"):
        p = tension.case(base, ref_speed, 0.0)
        sections = {"quasi_static": steps}
        if scheme == "mixed":
            sections["mixed"] = {"unstable_rounds": 3, "kinetic_fraction": 0.05, "arrest_steps": 200}
        case_path = write_case(directory, p, scheme, {"integrator": scheme, "dt": "stable", "safety_factor": 0.8},
                               None, sections, history_every=1)
        r = run(args.solver, case_path, args.threads, repeat)
        rows.append(row(scheme, ref_speed, r, os.path.dirname(case_path), ref_speed, p["end"]))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="Error against run time and force evaluations: velocity Verlet and "
                                     "the adaptive step on a wave and a fracture problem (docs/accuracy.md).")
    parser.add_argument("--solver", default=pdsolve(), help="pdsolve to run")
    parser.add_argument("--threads", type=int, default=1,
                        help="OpenMP threads of every run (default 1: the clouds have 2880 and 3088 nodes)")
    parser.add_argument("--repeat", type=int, default=3, help="runs of a case shorter than 2 s; the fastest counts")
    parser.add_argument("--out", default=os.path.join(ROOT, "out", "bench"), help="where the csv, png and runs go")
    parser.add_argument("--quick", action="store_true", help="fewer runs, no repeats (a smoke test of the benchmark)")
    parser.add_argument("--problems", default=",".join(PROBLEMS),
                        help=f"comma-separated subset of {', '.join(PROBLEMS)} (default: all)")
    quasi_static_cases.add_arguments(parser)
    args = parser.parse_args(argv)
    quasi_static_cases.settle_arguments(args)
    chosen = [name.strip() for name in args.problems.split(",") if name.strip()]
    unknown = sorted(set(chosen) - set(PROBLEMS))
    if unknown or not chosen:
        parser.error(f"--problems {args.problems}: unknown {', '.join(unknown) or 'empty list'}; "
                     f"choose from {', '.join(PROBLEMS)}")
    if not os.path.isfile(args.solver):
        parser.error(f"{args.solver} is missing: build it with `make solver`")
    # One writer per output folder, the lock make and peridyn take too (common/output_lock.py).
    with output_lock(args.out, "make bench-accuracy (bench.accuracy)"):
        return measure(args, chosen)


def measure(args, chosen):
    """The runs of main(), with the output folder locked."""
    repeat = 1 if args.quick else max(1, args.repeat)
    os.makedirs(args.out, exist_ok=True)
    load = os.getloadavg()[0]
    print(f"{machine()}; {args.threads} thread(s); load average {load:.2f} at the start", flush=True)
    rows = []
    for problem_name, make in (("wave", strip_problem), ("fracture", hole_problem)):
        if problem_name not in chosen:
            continue
        directory = os.path.join(args.out, problem_name)
        os.makedirs(directory, exist_ok=True)
        problem = make(directory)
        # Reference: Verlet at 1/16 of the default step, 0.8/16 = 0.05 × eq. 2.5 (docs/theory.md T18).
        ref_case = write_case(directory, problem, "reference",
                              {"integrator": "verlet", "dt": "stable", "safety_factor": 0.05}, None)
        ref = run(args.solver, ref_case, args.threads)
        if ref["status"] != "ok":
            raise SystemExit(f"{problem_name}: the reference run failed: {ref['status']}")
        reference = fields(os.path.dirname(ref_case), problem["measure"])
        dt_stable = stable_dt(ref["log"])
        print(f"{problem_name}: eq. 2.5 = {dt_stable:.4g} s; reference {ref['steps']} steps, {ref['wall']:.2f} s",
              flush=True)
        rows.append({"problem": problem_name, "scheme": "reference", "parameter": 0.05, "wall_time": ref["wall"],
                     "force_evaluations": ref["evaluations"], "steps": ref["steps"], "mean_dt": problem["end"] / ref["steps"],
                     "error": 0.0, "broken_bonds": ref["broken_bonds"], "status": "ok"})
        for scheme, parameter, time, adaptive in schemes(args.quick, dt_stable):
            name = f"{scheme}-{parameter:g}"
            case_path = write_case(directory, problem, name, time, adaptive)
            r = run(args.solver, case_path, args.threads, repeat)
            e = error(os.path.dirname(case_path), reference, problem["measure"]) if r["status"] == "ok" else float("nan")
            rows.append({"problem": problem_name, "scheme": scheme, "parameter": parameter, "wall_time": r["wall"],
                         "force_evaluations": r["evaluations"], "steps": r["steps"],
                         "mean_dt": problem["end"] / r["steps"] if r["steps"] else float("nan"), "error": e,
                         "broken_bonds": r["broken_bonds"], "status": r["status"]})
            print(f"  {name:32s} {r['status'][:6]:6s} steps {r['steps']:6d}  evals {r['evaluations']:6d}  "
                  f"wall {r['wall']:7.3f} s  error {e:.3g}", flush=True)
    if "tension" in chosen:
        tension_runs(args, repeat, rows)
    speedups = [quasi_static_cases.runs(args, rows, name) for name in quasi_static_cases.CASES if name in chosen]
    fieldnames = []
    for r in rows:
        fieldnames += [key for key in r if key not in fieldnames]
    with open(os.path.join(args.out, "accuracy.csv"), "w", newline="", encoding="utf-8") as stream:
        writer = csv.DictWriter(stream, fieldnames=fieldnames, restval="")
        writer.writeheader()
        writer.writerows(rows)
    plot(rows, os.path.join(args.out, "accuracy.png"), args.threads)
    print(f"wrote {args.out}/accuracy.csv and accuracy.png ({machine()}, {args.threads} thread(s), "
          f"load average {load:.2f} at the start, {os.getloadavg()[0]:.2f} at the end)")
    # One line per problem with a mixed row: the last lines of the output.
    for problem_name in ("tension",):
        line = tension.speedup_line(rows, problem_name)
        if line:
            print(line)
    for line in speedups:
        print(line)
    return 0


def plot(rows: list[dict], path: str, threads: int):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    problems = sorted({r["problem"] for r in rows}, reverse=True)
    fig, axes = plt.subplots(len(problems), 2, figsize=(11, 4.2 * len(problems)), squeeze=False)
    for row_axes, problem in zip(axes, problems):
        for ax, xkey, xlabel in zip(row_axes, ("wall_time", "force_evaluations"),
                                    (f"solver wall time [s] ({threads} thread{'s' if threads > 1 else ''})", "force evaluations")):
            for scheme in sorted({r["scheme"] for r in rows}):
                # joined in the order of the parameter (safety factor or TOL)
                pts = sorted(((r[xkey], r["error"], r["parameter"]) for r in rows
                             if r["problem"] == problem and r["scheme"] == scheme and r["status"] == "ok"
                             and r["scheme"] != "reference" and np.isfinite(r["error"]) and r["error"] > 0),
                             key=lambda p: p[2])
                if pts:
                    ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker="o", label=scheme)
                    for p in pts:
                        ax.annotate(f"{p[2]:g}", (p[0], p[1]), fontsize=6, xytext=(3, 3), textcoords="offset points")
            ax.set_xlabel(xlabel)
            ax.set_ylabel({"wave": "relative L2 error of displacement", "fracture": "relative L2 error of final damage",
                           }.get(problem, "relative error of the peak force"))
            ax.set_title(f"{problem}: error against {xlabel.split(' [')[0]}")
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    sys.exit(exit_code(main))
