"""Running pdsolve on a benchmark's case.json and reading what its run.log says: what the benchmarks
of bench/ share (accuracy, quasi_static_cases, explicit_reuse, implicit_dynamics), so that none of
them imports another for it. A run is pipeline/stages.py's solve stage; the counts are the `done:`
line's, which do not depend on the machine, and the time is the solver's own time-loop wall time.
"""
from __future__ import annotations

import os
import platform
import re

from pipeline import stages


def run_once(solver: str, case_path: str, threads: int) -> dict:
    """One run of case_path: its status ("ok", or "failed (exit code: last line of stderr)"), the
    counts of log_counts() and run.log's text."""
    result = stages.solve(case_path, solver=solver, threads=threads, quiet=True)
    try:
        with open(os.path.join(os.path.dirname(case_path), "run.log"), encoding="utf-8") as stream:
            log = stream.read()
    except OSError:
        log = ""
    counts = log_counts(log)
    if result.returncode != 0 or counts is None:
        last = (result.stderr.strip().splitlines() or ["no message"])[-1]
        return {"status": f"failed ({result.returncode}: {last[:80]})", "steps": 0, "wall": float("nan"),
                "evaluations": 0, "broken_bonds": -1, "log": log}
    return dict(counts, status="ok", log=log)


def log_counts(log: str) -> dict | None:
    """steps, wall (the time loop's), evaluations and broken_bonds from run.log's `done:` line;
    None when it has none."""
    done = re.search(r"(\d+) steps to t = \S+ s in ([0-9.]+) s wall.*?(\d+) force evaluations", log)
    if not done:
        return None
    broken = re.search(r"(\d+) broken bonds", log)
    return {"steps": int(done.group(1)), "wall": float(done.group(2)), "evaluations": int(done.group(3)),
            "broken_bonds": int(broken.group(1)) if broken else -1}


def run(solver: str, case_path: str, threads: int, repeat: int = 1) -> dict:
    """Run the case; rerun a run shorter than 2 s up to `repeat` times in all and keep the smallest
    wall time (the runs are deterministic: the same steps and force evaluations every time)."""
    best = run_once(solver, case_path, threads)
    for _ in range(repeat - 1):
        if best["status"] != "ok" or best["wall"] > 2.0:
            break
        again = run_once(solver, case_path, threads)
        if again["status"] != "ok" or (again["steps"], again["evaluations"]) != (best["steps"], best["evaluations"]):
            raise RuntimeError(f"{case_path}: a rerun differs ({again['status']}, {again['steps']} steps)")
        best["wall"] = min(best["wall"], again["wall"])
    return best


def stable_dt(log: str) -> float:
    """eq. 2.5 (without safety factor) as the solver computed it, from run.log's dt line."""
    found = re.search(r"\(stable (\S+) s", log)
    if not found:
        raise RuntimeError("run.log has no 'stable' time step")
    return float(found.group(1))


def machine() -> str:
    """The processor and its logical CPUs, for the first line of a benchmark's output."""
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as stream:
            found = re.search(r"model name\s*:\s*(.+)", stream.read())
            model = found.group(1).strip() if found else model
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} logical CPUs"
