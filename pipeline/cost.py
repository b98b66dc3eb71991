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
The limits are the issue's: more than MAX_HOURS hours, or more than half of the free memory or disk.
"""
from __future__ import annotations

import math
import os
import shutil

import numpy as np

from .yaml_lines import CaseError

BOND_RATE = 1.5e8            # directed bond updates per second in a whole step (see above)
MEMORY_PER_NODE = 105.0      # bytes (measured, see above)
MEMORY_PER_BOND = 5.07       # bytes per directed bond (measured)
FRAME_BYTES_PER_NODE = 25.0  # bytes per node and frame (measured)
HISTORY_ROW_BYTES = 150.0    # bytes per history.csv row (measured)
MAX_HOURS = 1.0


def _available_memory() -> float:
    """MemAvailable of /proc/meminfo [bytes], or infinity where it cannot be read."""
    try:
        with open("/proc/meminfo", encoding="ascii") as stream:
            for line in stream:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    return math.inf


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


def estimate(case: dict, cloud, directed_bonds: float, dt: float) -> dict:
    """The run's size: nodes, directed bonds, steps, frames, and bytes of memory and disk, seconds."""
    n = len(cloud.volume)
    time = case["time"]
    steps = min(math.ceil(float(time["end"]) / dt - 1e-9), int(time["max_steps"]))
    out = case["output"]
    if out["every_steps"] is not None:
        frames = steps // int(out["every_steps"]) + 2
    else:
        frames = math.floor(float(time["end"]) / float(out["every_time"]) + 1e-9) + 2
    rows = steps // int(out["history_every"]) + 1
    # Only Verlet's steps are known before the run; the adaptive, quasi-static and mixed integrators
    # choose theirs (and a quasi-static step costs a factorisation, not a sweep over the bonds).
    explicit = time["integrator"] == "verlet"
    return {"nodes": n, "bonds": directed_bonds, "steps": steps if explicit else None, "frames": frames,
            "memory": n * MEMORY_PER_NODE + directed_bonds * MEMORY_PER_BOND,
            "disk": frames * n * FRAME_BYTES_PER_NODE + (rows * HISTORY_ROW_BYTES if explicit else 0.0),
            "seconds": steps * directed_bonds / BOND_RATE if explicit else None}


def mean_bonds(points, tree, horizon: float, slack: float) -> float:
    """Mean bonds per node, counted on up to 5000 nodes spread over the cloud."""
    sample = np.linspace(0, len(points) - 1, min(len(points), 5000)).astype(np.int64)
    return float(np.mean(tree.query_ball_point(points[sample], horizon * slack, return_length=True) - 1))


def check_cost(case: dict, cost: dict, out_dir: str, force: bool | None = None) -> str:
    """The work-plan line; CaseError (naming time.end, the cost and FORCE=1) above a limit."""
    force = os.environ.get("FORCE") == "1" if force is None else force
    timing = (f"{cost['steps']} steps, " if cost["steps"] is not None else "") + f"{cost['frames']} frames"
    duration = (f", {_duration(cost['seconds'])} at {BOND_RATE:.2g} bond updates/s" if cost["seconds"] is not None
                else " (the integrator chooses its steps: no time estimate)")
    line = (f"work plan: {cost['nodes']} nodes, {cost['bonds']:.3g} bonds, {timing}; about "
            f"{cost['memory'] / 1e6:.0f} MB of memory, {cost['disk'] / 1e6:.0f} MB of disk{duration}")
    reasons = []
    if cost["seconds"] is not None and cost["seconds"] > MAX_HOURS * 3600:
        reasons.append(f"it would run about {_duration(cost['seconds'])} (more than {MAX_HOURS:g} h)")
    memory = _available_memory()
    if cost["memory"] > 0.5 * memory:
        reasons.append(f"it needs about {cost['memory'] / 1e6:.0f} MB of memory, more than half of the "
                       f"{memory / 1e6:.0f} MB available")
    disk = _free_disk(out_dir)
    if cost["disk"] > 0.5 * disk:
        reasons.append(f"it writes about {cost['disk'] / 1e6:.0f} MB, more than half of the {disk / 1e6:.0f} MB "
                       f"free in {out_dir}")
    if reasons and not force:
        lines = case.get("_lines", {})
        raise CaseError(f"{case.get('_path', '<case>')}:{lines.get(('time', 'end'), 1)}: {line}; "
                        + "; ".join(reasons) + ": coarsen discretization.dx, shorten time.end or write fewer "
                        "frames, or run it anyway with FORCE=1 (make FORCE=1 case=...)")
    return line
