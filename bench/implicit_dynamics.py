"""Implicit dynamics against Verlet on the drum and the membrane (make bench-implicit; issue 13): a lattice model of
cases/drum — a square membrane pre-strained by ε0 = 10⁻³ inside a clamped frame, struck with
v_z = 0.1 m/s, ringing out of plane at a frequency set by the tension (the membrane wave speed
√(Eε0/((1−ν)ρ)) ≈ 61 m/s is 1/26 of the in-plane wave speed that sets the explicit limit, so the
motion is slow for the explicit step). A benchmark, not a test: it asserts nothing.

Runs: velocity Verlet at several fractions of eq. 2.5, and time.integrator: implicit (generalized-α,
ρ∞ = 1 and 0.8) over a sweep of implicit.tol. Error: the relative L2 norm of the out-of-plane
displacement u_z over the saved frames, sqrt(Σ_frames Σ_nodes (w − w_ref)² / Σ_frames Σ_nodes w_ref²),
against Verlet at 0.05 × eq. 2.5 (frames in float64). Cost: the solver's time-loop wall time (run.log's
`done:` line; the minimum of --repeat runs for a run shorter than 2 s) and its force evaluations
(Newton iterations and rejected attempts included; a factorisation is not a force evaluation, its
time is in the wall time).

Writes out/bench/implicit.csv (a row per run) and prints a table.

Measured once (2 Dec 2026, 1 thread, the 2-core machine at load 11–15 from other jobs; span 30 dx =
1369 nodes, 2 periods): Verlet at 0.8 × eq. 2.5 has error 6.1e-5 (blow) and 1.1e-5 (pulse) in
2440 evaluations, 1.6–1.9 s. Implicit (ρ∞ = 1) at tol 1e-2 / 1e-3 / 1e-4: blow 571 / 1424 / 3756
evaluations, error 4.5e-2 / 5.4e-3 / 5.5e-4, 14–18 s; pulse 365 / 881 / 2408 evaluations, error
3.9e-2 / 4.3e-3 / 4.8e-4, 18–31 s (mean Δt 21 / 7.7 / 2.6 × eq. 2.5). At span 60 (4489 nodes, pulse,
1 period): Verlet 2440 evaluations, 1.7e-6, 4.4 s; implicit tol 1e-2: 286 evaluations (Δt 28 ×
eq. 2.5), 1.9e-2, 130 s. Fewer force evaluations, but each CHOLMOD factorisation (78 of them in the
span-30 pulse run at tol 1e-3; 45 % of its time in dsyrk/dgemm/dtrsm of Debian's reference BLAS, the
force 2.5 %) costs hundreds of force evaluations, and Verlet at its limit is already far more
accurate than the slow motion needs: implicit does not win here.

And cases/membrane on its own lattice (--loads membrane, 2500 nodes, to --membrane-end 2 ms): measured
4 Dec 2026 (docs/notes/2026-12-02-implicit-dynamics.md), Verlet at 0.8 × eq. 2.5 7.1e-3 in 1.1 s;
implicit at tol 1e-2 6.3e-2 in 8.7 s, at 1e-5 8.9e-4 in 54.7 s: Verlet wins here too.

    /usr/bin/python3 -m bench.implicit_dynamics [--solver build/solver/pdsolve] [--threads 1]
        [--repeat 3] [--span 30] [--periods 2] [--loads blow,pulse,membrane] [--membrane-end 2e-3]
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import sys

import numpy as np

from bench.solver_runs import machine, run, stable_dt
from common.output_lock import exit_code, output_lock
from common.paths import REPOSITORY as ROOT, pdsolve
from postprocess.series import read_frame, read_series
from preprocess.cloud import NodeCloud
from preprocess.node_file import write_node_file

L = 0.05           # m: free span, as cases/drum
EPS0 = 1.0e-3      # pre-strain
FRAME_LAYERS = 3   # clamped rows on each side (≥ δ = 3.015 dx)
PERIOD = 1.155e-3  # s: the fundamental of cases/drum (README), for the run's length


def drum_problem(directory: str, span: int, periods: float, load: str) -> dict:
    """The drum on a lattice of span × span free cells plus the frame: nodes.vtu and the case's parts.
    load "blow": cases/drum's uniform v_z = 0.1 m/s at t = 0, whose jump at the frame excites every
    membrane mode up to the grid's; "pulse": a smooth pressure, a Hann pulse of body force in z over
    half a fundamental period (peak 4·10⁵ N/m³, about the same deflection), which rings mostly in the
    low modes."""
    dx = L / span
    n = span + 1 + 2 * FRAME_LAYERS
    x, y = np.meshgrid(np.arange(n) * dx, np.arange(n) * dx, indexing="xy")
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    edge = FRAME_LAYERS * dx - 0.5 * dx
    far = (n - 1) * dx - edge
    frame = (points[:, 0] < edge) | (points[:, 0] > far) | (points[:, 1] < edge) | (points[:, 1] > far)
    cloud = NodeCloud(points=points, volume=np.full(len(points), dx * dx * 1e-3), block=np.ones(len(points), np.int32),
                      sets={"all": np.ones(len(points), bool), "frame": frame}, grid_spacing=dx, dimension=2)
    write_node_file(os.path.join(directory, "nodes.vtu"), cloud)
    end = periods * PERIOD
    pulse_times = np.linspace(0.0, 0.5 * PERIOD, 21)
    return {
        "dimension": 2, "analysis": "plane_stress", "thickness": 1e-3, "grid_spacing": dx, "horizon": 3.015 * dx,
        "blocks": [{"id": 1, "name": "membrane", "model": "pmb", "density": 1200.0, "youngs_modulus": 3.0e9,
                    "fracture_energy": None}],
        "node_sets": ["all", "frame"],
        "initial_conditions": [
            {"set": "all", "kind": "displacement", "component": 0, "value": 0.0, "gradient": EPS0},
            {"set": "all", "kind": "displacement", "component": 1, "value": 0.0, "gradient": EPS0}]
        + ([{"set": "all", "kind": "velocity", "component": 2, "value": 0.1}] if load == "blow" else []),
        "boundary_conditions": [{"set": "frame", "kind": "velocity", "component": c, "times": [0.0], "values": [0.0]}
                                for c in range(3)]
        + ([{"set": "all", "kind": "body_force", "component": 2, "times": pulse_times.tolist(),
             "values": (4e5 * np.sin(np.pi * pulse_times / pulse_times[-1]) ** 2).tolist()}] if load == "pulse" else []),
        "end": end, "every_time": end / 20, "nodes": len(points),
    }


MEMBRANE_SIDE = 50       # nodes per side of cases/membrane's lattice (dx = 1 mm)
MEMBRANE_DX = 1.0e-3


def membrane_problem(directory: str, end: float) -> dict:
    """cases/membrane on its lattice (50 × 50 nodes, dx = 1 mm, δ = 3.015 dx): clamped in a layer 3 mm
    deep along the four sides, a central disk of radius 6 mm set moving out of plane at 10 m/s,
    velocity damping 300 1/s, no pre-strain: the membrane resists out-of-plane motion only through
    the stretch its deflection causes (thesis §5.1), so its motion is slow and nonlinear next to the
    in-plane waves that set the explicit limit."""
    dx, n = MEMBRANE_DX, MEMBRANE_SIDE
    x, y = np.meshgrid(np.arange(n) * dx, np.arange(n) * dx, indexing="xy")
    points = np.column_stack([x.ravel() + 0.5 * dx, y.ravel() + 0.5 * dx, np.zeros(x.size)])
    side = n * dx
    clamped = ((points[:, 0] < 3e-3) | (points[:, 0] > side - 3e-3) | (points[:, 1] < 3e-3) | (points[:, 1] > side - 3e-3))
    centre = np.hypot(points[:, 0] - side / 2, points[:, 1] - side / 2) < 6e-3
    cloud = NodeCloud(points=points, volume=np.full(len(points), dx * dx * 1e-3), block=np.ones(len(points), np.int32),
                      sets={"clamped": clamped, "centre": centre}, grid_spacing=dx, dimension=2)
    write_node_file(os.path.join(directory, "nodes.vtu"), cloud)
    return {
        "dimension": 2, "analysis": "plane_stress", "thickness": 1e-3, "grid_spacing": dx, "horizon": 3.015 * dx,
        "blocks": [{"id": 1, "name": "membrane", "model": "pmb", "density": 1200.0, "youngs_modulus": 3.0e9,
                    "fracture_energy": None}],
        "node_sets": ["clamped", "centre"],
        "initial_conditions": [{"set": "centre", "kind": "velocity", "component": 2, "value": 10.0}],
        "boundary_conditions": [{"set": "clamped", "kind": "velocity", "component": c, "times": [0.0], "values": [0.0]}
                                for c in range(3)],
        "damping": 300.0, "end": end, "every_time": end / 20, "nodes": len(points),
    }


def write_case(directory: str, problem: dict, name: str, time: dict, implicit: dict | None) -> str:
    run_dir = os.path.join(directory, name)
    os.makedirs(run_dir, exist_ok=True)
    case = {key: problem[key] for key in ("dimension", "analysis", "thickness", "grid_spacing", "horizon", "blocks",
                                          "node_sets", "boundary_conditions", "initial_conditions")}
    case.update({"format_version": 1, "case": name, "nodes_file": "../nodes.vtu", "output_dir": ".",
                 "no_fail_sets": [], "damping": problem.get("damping", 0.0),
                 "time": dict(time, end=problem["end"], max_steps=10_000_000),
                 "output": {"every_time": problem["every_time"], "every_steps": None, "history_every": 1_000_000,
                            "precision": "float64"}})
    if implicit:
        case["implicit"] = implicit
    path = os.path.join(run_dir, "case.json")
    with open(path, "w", encoding="utf-8") as stream:
        json.dump(case, stream, indent=1)
    return path


def out_of_plane(run_dir: str) -> list[np.ndarray]:
    frames = read_series(os.path.join(run_dir, "frames.pvd"))
    return [read_frame(os.path.join(run_dir, path)).displacement[:, 2] for _time, path in frames]


def error(run_dir: str, reference: list[np.ndarray]) -> float:
    got = out_of_plane(run_dir)
    if len(got) != len(reference):
        return float("nan")
    num = sum(float(np.sum((a - b) ** 2)) for a, b in zip(got, reference))
    den = sum(float(np.sum(b ** 2)) for b in reference)
    return (num / den) ** 0.5


def schemes(factors: list[float], rhos: list[float], tols: list[float]):
    """(scheme, parameter, time section, implicit section) of every run."""
    for f in factors:
        yield "verlet", f, {"integrator": "verlet", "dt": "stable", "safety_factor": f}, None
    for rho in rhos:
        for tol in tols:
            yield (f"implicit-rho{rho:g}", tol, {"integrator": "implicit", "dt": "stable", "safety_factor": 0.8},
                   {"rho_infinity": rho, "tol": tol})


def bench_load(args, load: str) -> list[dict]:
    directory = os.path.join(args.out, "implicit", load)
    os.makedirs(directory, exist_ok=True)
    if load == "membrane":
        problem = membrane_problem(directory, args.membrane_end)
        print(f"cases/membrane's lattice: {problem['nodes']} nodes, to t = {args.membrane_end:g} s; "
              f"{machine()}, {args.threads} thread(s); load {os.getloadavg()[0]:.2f}")
    else:
        problem = drum_problem(directory, args.span, args.periods, load)
        print(f"drum lattice, {load}: {problem['nodes']} nodes, span {args.span} dx, {args.periods:g} periods; "
              f"{machine()}, {args.threads} thread(s); load {os.getloadavg()[0]:.2f}")

    reference_path = write_case(directory, problem, "reference", {"integrator": "verlet", "dt": "stable",
                                                                  "safety_factor": 0.05}, None)
    reference_run = run(args.solver, reference_path, args.threads)
    if reference_run["status"] != "ok":
        raise RuntimeError(f"the reference run failed: {reference_run['status']}")
    reference = out_of_plane(os.path.dirname(reference_path))
    dt_stable = stable_dt(reference_run["log"])

    rows = []
    numbers = lambda text: [float(v) for v in text.split(",")]  # noqa: E731
    for scheme, parameter, time, implicit in schemes(numbers(args.verlet), numbers(args.rho), numbers(args.tols)):
        name = f"{scheme}-{parameter:g}"
        path = write_case(directory, problem, name, time, implicit)
        result = run(args.solver, path, args.threads, args.repeat)
        rows.append({"load": load, "scheme": scheme, "parameter": parameter, "status": result["status"],
                     "steps": result["steps"],
                     "mean_dt_over_eq2.5": (problem["end"] / result["steps"] / dt_stable) if result["steps"] else "",
                     "wall_s": result["wall"], "force_evaluations": result["evaluations"],
                     "error_uz": error(os.path.dirname(path), reference) if result["status"] == "ok" else float("nan"),
                     "machine_load": f"{os.getloadavg()[0]:.2f}"})
    print(f"reference: Verlet at 0.05 × eq. 2.5 (eq. 2.5 = {dt_stable:.4g} s), {reference_run['steps']} steps, "
          f"{reference_run['wall']:.2f} s")
    print(f"{'scheme':<16}{'parameter':>10}{'steps':>8}{'Δt/eq.2.5':>11}{'wall [s]':>10}{'force ev.':>11}{'error u_z':>12}")
    for r in rows:
        ratio = f"{r['mean_dt_over_eq2.5']:.2f}" if r["steps"] else "-"
        print(f"{r['scheme']:<16}{r['parameter']:>10g}{r['steps']:>8}{ratio:>11}{r['wall_s']:>10.3f}"
              f"{r['force_evaluations']:>11}{r['error_uz']:>12.3g}  {r['status'] if r['status'] != 'ok' else ''}")
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--solver", default=pdsolve(), help="pdsolve to run")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--span", type=int, default=30, help="free span in grid spacings (cases/drum: 100)")
    parser.add_argument("--periods", type=float, default=2.0, help="length of the run in fundamental periods")
    parser.add_argument("--loads", default="blow,pulse,membrane",
                        help="blow (cases/drum's), pulse (smooth), membrane (cases/membrane's), comma-separated")
    parser.add_argument("--membrane-end", type=float, default=2e-3, help="the membrane run's end time [s]")
    parser.add_argument("--verlet", default="0.8,0.4,0.2", help="Verlet's steps as fractions of eq. 2.5")
    parser.add_argument("--rho", default="1,0.8", help="implicit.rho_infinity values")
    parser.add_argument("--tols", default="1e-2,1e-3,1e-4,1e-5", help="implicit.tol values")
    parser.add_argument("--out", default=os.path.join(ROOT, "out", "bench"))
    args = parser.parse_args(argv)
    # One writer per output folder, the lock make and peridyn take too (common/output_lock.py).
    with output_lock(args.out, "make bench-implicit (bench.implicit_dynamics)"):
        return measure(args)


def measure(args):
    """The runs of main(), with the output folder locked."""
    rows = []
    for load in args.loads.split(","):
        rows += bench_load(args, load)
    csv_path = os.path.join(args.out, "implicit.csv")
    with open(csv_path, "w", newline="", encoding="utf-8") as stream:
        writer = csv.DictWriter(stream, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"wrote {csv_path}")
    return 0


if __name__ == "__main__":
    sys.exit(exit_code(main))
