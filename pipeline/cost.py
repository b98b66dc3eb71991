"""The cost of a run, estimated before it is spent (issue 17, item 11): nodes, bonds, steps, memory,
disk and time, printed by the preprocess stage; a run above a limit stops there unless FORCE=1.

Before, `dx: 2e-5` made 6.25·10⁶ nodes and 879,446 steps (about 25 days here) and wrote 1 GB
before anyone was told. The figures are estimates from rates measured on this project:
- time: directed bond updates per second of a whole explicit step, BOND_RATE. The bond kernel
  alone runs 2.6–5.6·10⁸ per second on 1–2 threads (docs/performance.md); whole runs' done: lines
  gave 2.66·10⁸ (branching) and 1.01·10⁸ (membrane, 2 500 nodes) with 2 threads on a quiet machine;
- memory: MEMORY_PER_NODE and MEMORY_PER_BOND from the measured peak of docs/performance.md: 723 MB
  at 10⁶ nodes and 122 directed bonds per node, 5.07 B per directed bond and the rest (≈ 105 B) per
  node;
- disk: FRAME_BYTES_PER_NODE per frame, measured on the default float32 + zlib frames: 22 B per node
  (branching, broken-bond lines included) and 25 B (membrane); HISTORY_ROW_BYTES per history.csv
  row, measured 132 B (membrane) and 150 B (branching, with its reaction columns).
- time of the Newton integrators (quasi_static, implicit, and mixed's quasi-static or implicit
  steps; issue 36, item 12: a 100-day implicit run and the ~4 h beam_3d were accepted with "no time
  estimate"): NEWTON_STEP_SECONDS_PER_BOND, the wall time of one load or time step per directed bond,
  measured on this machine (2 threads, load average 5–7, pdsolve of this branch's base) on the shipped
  Newton cases: 2D, cases/traction quasi_static.yaml (30 336 nodes, 8.29·10⁵ bonds, CHOLMOD): 120
  steps, crack growth included, in 346 s: 3.5·10⁻⁶ s; 3D, cases/beam_3d coarse.yaml (16 000 nodes,
  1.55·10⁶ bonds, CG with AMG): its first 19 steps, 8–12 Newton iterations each, in 417 s: 1.4·10⁻⁵ s.
  The steps: a load step of quasi_static grows at most 2× per step from dt_initial up to dt_max
  (integrators/quasi_static.cpp), so newton_steps() counts the fewest steps the run can take; an
  implicit step is also held by its error estimate: on cases/membrane (make bench-implicit,
  docs/accuracy.md) its mean was IMPLICIT_STEP_PER_EQ25 = 2 × eq. 2.5 at tol 10⁻³, growing as
  tol^0.55 (7.25× at 10⁻², 0.6× at 10⁻⁴); measured again here on cases/membrane with
  integrator: implicit: 3 286 steps to 4.53 ms, mean 1.9 × eq. 2.5, 0.15 s per step at load 6
  (2.2·10⁻⁶ s per step and bond, near the 2D figure). A smooth load allows longer implicit steps.
  The quasi-static count is the fewest steps (cuts and re-solves add more: traction took 120 for 70),
  and mixed's explicit phases (while a crack runs) are not counted: both are lower bounds ("at least").
  These rates were measured on the shared machine under load; a quiet one runs several times faster.
The limits are the issue's: more than MAX_HOURS hours, or more than half of the free memory or disk.
"""
from __future__ import annotations

import math
import os
import shutil

import numpy as np

from common.memory import available_memory

from .validate import MAX_FRAMES
from .yaml_lines import CaseError

BOND_RATE = 1.5e8            # directed bond updates per second in a whole step (see above)
MEMORY_PER_NODE = 105.0      # bytes (measured, see above)
MEMORY_PER_BOND = 5.07       # bytes per directed bond (measured)
FRAME_BYTES_PER_NODE = 25.0  # bytes per node and frame (measured)
HISTORY_ROW_BYTES = 150.0    # bytes per history.csv row (measured)
MAX_HOURS = 1.0
NEWTON_STEP_SECONDS_PER_BOND = {2: 3.5e-6, 3: 1.4e-5}   # by dimension (measured, see above)
IMPLICIT_STEP_PER_EQ25 = 2.0       # mean implicit Δt / eq. 2.5 at tol 1e-3 (measured, see above)
IMPLICIT_TOL_EXPONENT = 0.55       # ... and how it grows with tol


def _free_disk(folder: str) -> float:
    folder = os.path.abspath(folder)
    while not os.path.isdir(folder):
        folder = os.path.dirname(folder)
    try:
        return float(shutil.disk_usage(folder).free)
    except OSError:
        return math.inf


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 2 * 3600:
        return f"{seconds / 60:.0f} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.1f} days"


def load_steps(end: float, first: float, largest: float) -> int:
    """The fewest steps from 0 to `end` that start at `first` and at most double per step up to
    `largest` (the step control of the Newton integrators)."""
    t, h, steps = 0.0, min(first, largest), 0
    while t < end and h < largest:   # at most log2(largest/first) doublings
        t, h, steps = t + h, min(2.0 * h, largest), steps + 1
    if t < end:
        steps += math.ceil((end - t) / largest - 1e-9)
    return max(steps, 1)


def newton_steps(case: dict, dt: float, dt_eq25: float | None) -> tuple[int | None, str | None]:
    """(steps, scheme) of the quasi-static or implicit steps the run takes, or (None, None) for
    the explicit integrators. dt: the explicit step (implicit's first step by default); dt_eq25:
    eq. 2.5's step, which sets the implicit step's accuracy limit (None: not known)."""
    time = case["time"]
    end, integrator = float(time["end"]), time["integrator"]
    scheme = case["mixed"]["start"] if integrator == "mixed" else integrator
    if scheme == "quasi_static":
        q = case["quasi_static"]
        largest = q["dt_max"] if q["dt_max"] is not None else end / 10.0
        first = q["dt_initial"] if q["dt_initial"] is not None else end / 100.0
        return load_steps(end, first, largest), scheme
    if scheme == "implicit":
        m = case["implicit"]
        largest = m["dt_max"] if m["dt_max"] is not None else end / 10.0
        first = m["dt_initial"] if m["dt_initial"] is not None else dt
        steps = load_steps(end, first, largest)
        if dt_eq25 is not None and dt_eq25 > 0 and math.isfinite(dt_eq25):
            accurate = IMPLICIT_STEP_PER_EQ25 * dt_eq25 * (float(m["tol"]) / 1e-3) ** IMPLICIT_TOL_EXPONENT
            steps = max(steps, math.ceil(end / min(accurate, largest) - 1e-9))
        return steps, scheme
    return None, None


def estimate(case: dict, cloud, directed_bonds: float, dt: float, dt_eq25: float | None = None) -> dict:
    """The run's size: nodes, directed bonds, steps, frames, and bytes of memory and disk, seconds.

    `seconds` is None where no estimate is made (the adaptive integrator); `at_least` says it is a
    lower bound (mixed: its explicit phases are not counted)."""
    n = len(cloud.volume)
    time = case["time"]
    steps = min(math.ceil(float(time["end"]) / dt - 1e-9), int(time["max_steps"]))
    out = case["output"]
    if out["every_steps"] is not None:
        frames = steps // int(out["every_steps"]) + 2
    else:
        frames = math.floor(float(time["end"]) / float(out["every_time"]) + 1e-9) + 2
    # Verlet's steps are known before the run; the Newton integrators' are estimated (newton_steps);
    # the adaptive integrator chooses its own, and no time is estimated for it.
    explicit = time["integrator"] == "verlet"
    newton, scheme = newton_steps(case, dt, dt_eq25)
    if newton is not None:
        steps = min(newton, int(time["max_steps"]))
        seconds = steps * directed_bonds * NEWTON_STEP_SECONDS_PER_BOND[int(case["dimension"])]
    elif explicit:
        seconds = steps * directed_bonds / BOND_RATE
    else:
        steps, seconds = None, None
    rows = steps // int(out["history_every"]) + 1 if steps is not None else 0
    return {"nodes": n, "bonds": directed_bonds, "steps": steps, "frames": frames, "scheme": scheme,
            "at_least": time["integrator"] == "mixed" or scheme == "quasi_static",
            "memory": n * MEMORY_PER_NODE + directed_bonds * MEMORY_PER_BOND,
            "disk": frames * n * FRAME_BYTES_PER_NODE + rows * HISTORY_ROW_BYTES,
            "seconds": seconds}


def mean_bonds(points, tree, horizon: float, slack: float) -> float:
    """Mean bonds per node, counted on up to 5000 nodes spread over the cloud."""
    sample = np.linspace(0, len(points) - 1, min(len(points), 5000)).astype(np.int64)
    return float(np.mean(tree.query_ball_point(points[sample], horizon * slack, return_length=True) - 1))


def check_cost(case: dict, cost: dict, out_dir: str, force: bool | None = None) -> str:
    """The work-plan line; CaseError (naming time.end, the cost and FORCE=1) above a limit."""
    force = os.environ.get("FORCE") == "1" if force is None else force
    scheme = cost.get("scheme")
    about = "at least " if cost.get("at_least") else ""
    if cost["steps"] is None:
        timing = ""
    elif scheme is None:
        timing = f"{cost['steps']} steps, "
    else:
        timing = f"{about}{cost['steps']} {'load' if scheme == 'quasi_static' else 'implicit'} steps, "
    timing += f"{cost['frames']} frames"
    if cost["seconds"] is None:
        duration = " (the integrator chooses its steps: no time estimate)"
    elif scheme is None:
        duration = f", {_duration(cost['seconds'])} at {BOND_RATE:.2g} bond updates/s"
    else:
        rate = cost["seconds"] / max(cost["steps"] * cost["bonds"], 1e-300)
        duration = (f", {about}{_duration(cost['seconds'])} at {rate:.2g} s per step and bond (measured on the "
                    "shipped Newton cases" + ("; the explicit phases not counted)"
                                             if case["time"]["integrator"] == "mixed" else ")"))
    line = (f"work plan: {cost['nodes']} nodes, {cost['bonds']:.3g} bonds, {timing}; about "
            f"{cost['memory'] / 1e6:.0f} MB of memory, {cost['disk'] / 1e6:.0f} MB of disk{duration}")
    reasons = []
    if cost["seconds"] is not None and cost["seconds"] > MAX_HOURS * 3600:
        reasons.append(f"it would run {'at least' if cost.get('at_least') else 'about'} "
                       f"{_duration(cost['seconds'])} (more than {MAX_HOURS:g} h)")
    memory = available_memory()
    if cost["memory"] > 0.5 * memory:
        reasons.append(f"it needs about {cost['memory'] / 1e6:.0f} MB of memory, more than half of the "
                       f"{memory / 1e6:.0f} MB available")
    if cost["frames"] > MAX_FRAMES:  # output.every_steps (every_time is checked with the case file)
        reasons.append(f"it writes about {cost['frames']} frames (more than {MAX_FRAMES}, each read and drawn "
                       "from by postprocess): raise output.every_steps")
    disk = _free_disk(out_dir)
    if cost["disk"] > 0.5 * disk:
        reasons.append(f"it writes about {cost['disk'] / 1e6:.0f} MB, more than half of the {disk / 1e6:.0f} MB "
                       f"free in {out_dir}")
    if reasons and not force:
        lines = case.get("_lines", {})
        steps_hint = (f", allow longer steps ({scheme}.dt_max{', tol' if scheme == 'implicit' else ''})"
                      if scheme else "")
        raise CaseError(f"{case.get('_path', '<case>')}:{lines.get(('time', 'end'), 1)}: {line}; "
                        + "; ".join(reasons) + f": coarsen discretization.dx, shorten time.end{steps_hint} or "
                        "write fewer frames, or run it anyway with FORCE=1 (make FORCE=1 case=...)")
    return line
