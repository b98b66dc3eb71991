"""The third problem of bench/accuracy.py: quasi-static tension with fracture (issue 13).

A single-edge-notched PMMA strip is pulled by its grips until it breaks. Measured on every run:
the peak force, the grip displacement at the peak, the force–displacement curve up to the
reference's peak (relative L2), and where the crack crosses the strip. The reference is the
explicit run (velocity Verlet, damped at 0.1 of critical in the first axial mode) whose loading rate
has converged: the script halves the grip speed until halving it changes the peak by less than
0.5 %, and takes the slower run.

The cost of a run with a linear solver is counted in force-evaluation equivalents: its force
evaluations, plus the wall time of its factorisations and solves (run.log's done: line) divided by
the wall time of one force evaluation, measured on the explicit reference of the same problem
(wall / evaluations: a Verlet step is one force evaluation and little else).
"""
from __future__ import annotations

import csv
import math
import os
import re

import numpy as np

from postprocess.series import read_frame, read_series
from preprocess.cloud import NodeCloud
from preprocess.node_file import write_node_file

DX = 1.0e-3
NX, NY = 60, 20              # nodes: the strip is 59 mm × 19 mm
NOTCH = 4.5 * DX             # the pre-crack from the lower edge, between node columns 29 and 30
GRIP_COLUMNS = 3             # no-fail grips, displaced along x and held in y
END_DISPLACEMENT = 7.5e-5    # m, each grip: some 15 % past the peak (0.065 mm): a slow run is cut through by then
RAMP_FRACTION = 0.2          # the grip speed ramps up linearly over this fraction of the run
DENSITY, YOUNGS = 1190.0, 3.2e9
BAR_SPEED = math.sqrt(YOUNGS / DENSITY)             # m/s
OMEGA_1 = math.pi * BAR_SPEED / ((NX - 1) * DX)     # first axial mode of the free strip [rad/s]
REFERENCE_ZETA = 0.1         # the reference's damping, a fraction of critical in the first axial mode
PEAK_CONVERGED = 5e-3        # halving the rate changes the peak by less than this: the reference
PEAK_TOLERANCE = 0.02        # "as accurate as mixed": the peak within 2 % of the reference's
CRACK_TOLERANCE = 2 * DX     # and the crack within 2 dx of the reference's, cut through alike


def write_nodes(directory: str) -> None:
    x, y = np.meshgrid(np.arange(NX) * DX, np.arange(NY) * DX, indexing="xy")
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    left, right = points[:, 0] < (GRIP_COLUMNS - 0.5) * DX, points[:, 0] > (NX - GRIP_COLUMNS - 0.5) * DX
    cloud = NodeCloud(points=points, volume=np.full(len(points), DX * DX * 1e-3), block=np.ones(len(points), np.int32),
                      sets={"left": left, "right": right}, grid_spacing=DX, dimension=2)
    write_node_file(os.path.join(directory, "nodes.vtu"), cloud)


def end_time(speed: float) -> float:
    """The time at which a grip moving at `speed` after the ramp has moved END_DISPLACEMENT:
    d(t) = v t²/(2 t_r) during the ramp t_r = RAMP_FRACTION·end, v (t − t_r/2) after it."""
    return END_DISPLACEMENT / (speed * (1.0 - RAMP_FRACTION / 2.0))


def grip_displacement(t: np.ndarray, speed: float, end: float) -> np.ndarray:
    ramp = RAMP_FRACTION * end
    return np.where(t < ramp, speed * t * t / (2.0 * ramp), speed * (t - ramp / 2.0))


def problem(directory: str) -> dict:
    """An 60 × 20 node strip (dx = 1 mm, 1200 nodes), PMMA (E = 3.2 GPa, ρ = 1190 kg/m³,
    G0 = 300 J/m², s0 = 6.6·10⁻³), a pre-crack of 4.5 dx from the lower edge at mid-length. The
    grips (3 node columns each end, no-fail) move apart along x, each at a speed ramped up over the
    first fifth of the run, and are held in y; the run ends when each has moved 0.075 mm."""
    write_nodes(directory)
    middle = (NX - 1) * DX / 2.0
    return {
        "dimension": 2, "analysis": "plane_stress", "thickness": 1e-3, "grid_spacing": DX, "horizon": 3.015 * DX,
        "blocks": [{"id": 1, "name": "pmma", "model": "pmb", "density": DENSITY, "youngs_modulus": YOUNGS,
                    "fracture_energy": 300.0}],
        "node_sets": ["left", "right"], "no_fail_sets": ["left", "right"],
        "cracks": [{"from": [middle, -0.5 * DX, 0.0], "to": [middle, NOTCH, 0.0]}],
    }


def case(problem_: dict, speed: float, damping: float) -> dict:
    """The problem loaded at `speed` [m/s] per grip with damping α [1/s]: end time, conditions."""
    end = end_time(speed)
    ramp = [0.0, RAMP_FRACTION * end]
    return dict(problem_, end=end, every_time=end, damping=damping, measure="tension", speed=speed,
                boundary_conditions=[
                    {"set": "left", "kind": "velocity", "component": 0, "times": ramp, "values": [0.0, -speed]},
                    {"set": "left", "kind": "displacement", "component": 1, "times": [0.0], "values": [0.0]},
                    {"set": "right", "kind": "velocity", "component": 0, "times": ramp, "values": [0.0, speed]},
                    {"set": "right", "kind": "displacement", "component": 1, "times": [0.0], "values": [0.0]}])


def curve(run_dir: str, speed: float, end: float) -> tuple[np.ndarray, np.ndarray]:
    """(grip displacement [m], reaction on the right grip along x [N]) of every history row."""
    with open(os.path.join(run_dir, "history.csv"), newline="", encoding="utf-8") as stream:
        rows = list(csv.DictReader(stream))
    t = np.array([float(r["time"]) for r in rows])
    force = np.array([float(r["reaction_right_fx"]) for r in rows])
    return grip_displacement(t, speed, end), force


def peak(displacement: np.ndarray, force: np.ndarray) -> tuple[float, float, int]:
    """(peak force, displacement at it, its row): the largest force before the strip breaks, the
    first time the force falls below half its largest value so far. After that the reaction is
    that of the broken halves' vibration (in an undamped run it can exceed the static peak)."""
    largest, at = -math.inf, 0
    for k, f in enumerate(force):
        if f > largest:
            largest, at = f, k
        elif largest > 0.0 and f < 0.5 * largest:
            break
    return float(force[at]), float(displacement[at]), at


def curve_error(displacement, force, reference_displacement, reference_force) -> float:
    """Relative L2 of the force over the reference's displacements up to its peak (the run's curve
    interpolated there; beyond the run's own peak its force is that of the broken strip)."""
    _, _, k_ref = peak(reference_displacement, reference_force)
    d_ref, f_ref = reference_displacement[: k_ref + 1], reference_force[: k_ref + 1]
    f = np.interp(d_ref, displacement, force)
    return float(np.linalg.norm(f - f_ref) / np.linalg.norm(f_ref))


def crack(run_dir: str) -> tuple[float, bool]:
    """(x of the crack [m], cut through): the mean x of the nodes with damage ≥ 0.3 in the last
    frame, and whether such nodes reach the upper edge's node row (the crack crossed the strip)."""
    frames = read_series(os.path.join(run_dir, "frames.pvd"))
    frame = read_frame(os.path.join(run_dir, frames[-1][1]))
    damaged = frame.damage >= 0.3
    if not np.any(damaged):
        return float("nan"), False
    x, y = frame.points[damaged, 0], frame.points[damaged, 1]
    return float(np.mean(x)), bool(np.max(y) >= (NY - 1.5) * DX)


def measures(run_dir: str, speed: float, end: float, reference=None) -> dict:
    d, f = curve(run_dir, speed, end)
    peak_force, peak_displacement, _ = peak(d, f)
    crack_x, cut = crack(run_dir)
    out = {"peak_force": peak_force, "peak_displacement": peak_displacement, "crack_x": crack_x, "cut": cut,
           "curve": (d, f)}
    if reference is not None:
        out["curve_error"] = curve_error(d, f, *reference["curve"])
        out["peak_error"] = abs(peak_force - reference["peak_force"]) / reference["peak_force"]
        out["same_crack"] = cut == reference["cut"] and abs(crack_x - reference["crack_x"]) <= CRACK_TOLERANCE
    return out


def linear_algebra(log: str) -> tuple[int, float, int, float]:
    """(factorisations, their wall time, solves, their wall time) from run.log's done: line (0s for a
    run without a linear solver)."""
    found = re.search(r"(\d+) factorisations in ([0-9.]+) s, (\d+) solves in ([0-9.]+) s", log)
    if not found:
        return 0, 0.0, 0, 0.0
    return int(found.group(1)), float(found.group(2)), int(found.group(3)), float(found.group(4))


def speedup_line(rows: list[dict], problem_name: str) -> str | None:
    """`speedup <problem>: mixed <s> s against explicit <s> s (<scheme, parameter>): <ratio>x, peak
    force <rel. error>`: explicit is the cheapest explicit row as accurate as mixed (peak within 2 %
    of the reference's, the same crack position)."""
    mine = [r for r in rows if r["problem"] == problem_name]
    mixed = [r for r in mine if r["scheme"] == "mixed" and r["status"] == "ok"]
    if not mixed:
        return None
    m = mixed[0]
    accurate = [r for r in mine if r["scheme"].startswith("verlet") and r["status"] == "ok"
                and r["peak_error"] <= PEAK_TOLERANCE and r["same_crack"]]
    if not accurate:
        return f"speedup {problem_name}: mixed {m['wall_time']:.3f} s against no explicit run as accurate"
    e = min(accurate, key=lambda r: r["wall_time"])
    return (f"speedup {problem_name}: mixed {m['wall_time']:.3f} s against explicit {e['wall_time']:.3f} s "
            f"({e['scheme']}, {e['parameter']:g} m/s): {e['wall_time'] / m['wall_time']:.3g}x, "
            f"peak force {m['peak_error']:.2e}")
