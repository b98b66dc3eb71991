"""Run a case, or a variant of it, through every stage exactly as the Makefile does (pipeline.run
mesh and preprocess, pdsolve, postprocess) into a chosen directory: the fast versions of the checks
in `make test` and the runs of `make validate` both use it."""
from __future__ import annotations

import copy
import os
import shutil
import subprocess
import time

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PY = "/usr/bin/python3"


def solver_path() -> str:
    """The pdsolve to run: $PDSOLVE if set, else the Makefile's build/solver/pdsolve."""
    return os.environ.get("PDSOLVE", os.path.join(ROOT, "build", "solver", "pdsolve"))


def deep_update(base: dict, changes: dict) -> dict:
    """base with changes merged in, recursively for sections (a value None deletes the key)."""
    out = copy.deepcopy(base)
    for key, value in changes.items():
        if value is None:
            out.pop(key, None)
        elif isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = deep_update(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def run_case(case: str, work: str, changes: dict | None = None, *, figures: bool = True,
             timeout: float = 1800.0, source: str | None = None, config: str | None = None) -> tuple[str, float]:
    """Copy cases/<case>/<case>.geo and the .yaml with `changes` merged in to work/cases/<case>/,
    run every stage into work/out/<case>/, and return (out_dir, solver wall seconds).
    source: another folder holding <case>.geo and <case>.yaml (validation/models/); config: the
    variant <config>.yaml of that folder instead of <case>.yaml (as `make case=X config=Y`)."""
    solver = solver_path()
    if not os.path.exists(solver):
        raise FileNotFoundError(f"{solver} is missing: build it with `make solver` (make test does)")
    source = source or os.path.join(ROOT, "cases", case)
    case_dir = os.path.join(work, "cases", case)
    os.makedirs(case_dir, exist_ok=True)
    shutil.copy(os.path.join(source, f"{case}.geo"), case_dir)
    with open(os.path.join(source, f"{config or case}.yaml"), encoding="utf-8") as stream:
        data = yaml.safe_load(stream)
    yaml_path = os.path.join(case_dir, f"{case}.yaml")
    with open(yaml_path, "w", encoding="utf-8") as stream:
        yaml.safe_dump(deep_update(data, changes or {}), stream)
    out = os.path.join(work, "out", case)
    env = dict(os.environ, PYTHONPATH=ROOT)
    stages = [
        (PY, "-m", "pipeline.run", "mesh", yaml_path, os.path.join(case_dir, f"{case}.geo"), os.path.join(out, "mesh.msh")),
        (PY, "-m", "pipeline.run", "preprocess", yaml_path, os.path.join(out, "mesh.msh"), out),
        (solver, os.path.join(out, "case.json"), "--quiet"),
    ]
    if figures:
        stages.append((PY, "-m", "postprocess", out))
    solver_seconds = 0.0
    for args in stages:
        start = time.monotonic()
        result = subprocess.run(list(args), cwd=ROOT, env=env, capture_output=True, text=True, timeout=timeout)
        if args[0] == solver:
            solver_seconds = time.monotonic() - start
        if result.returncode != 0:
            raise RuntimeError(f"{' '.join(args)} failed:\n{result.stdout}\n{result.stderr}")
    return out, solver_seconds


def geometry_parameters(out_dir: str) -> dict:
    """geometry.parameters of the case file that made out_dir (case.json `source`)."""
    import json
    with open(os.path.join(out_dir, "case.json"), encoding="utf-8") as stream:
        source = json.load(stream)["source"]
    path = source if os.path.isabs(source) else os.path.join(ROOT, source)
    with open(path, encoding="utf-8") as stream:
        return (yaml.safe_load(stream).get("geometry") or {}).get("parameters") or {}
