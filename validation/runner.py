"""Run a case, or a variant of it, through every stage the Makefile runs (pipeline/stages.py: mesh,
preprocess, solve, postprocess) into a chosen directory: the fast versions of the checks in
`make test` and the runs of `make validate` both use it."""
from __future__ import annotations

import contextlib
import copy
import io
import os
import shutil
import time

import yaml

from common.paths import REPOSITORY as ROOT, pdsolve
from pipeline import stages


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
    solver = pdsolve()
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
    mesh = os.path.join(out, "mesh.msh")
    quietly(f"mesh {yaml_path}", stages.mesh, yaml_path, os.path.join(case_dir, f"{case}.geo"), mesh)
    # preprocess asks the same solver for eq. 2.5's step (pdsolve --physics, pipeline/solver_physics.py)
    quietly(f"preprocess {yaml_path}", lambda: stages.preprocess(yaml_path, mesh, out, solver=solver))
    start = time.monotonic()
    result = stages.solve(os.path.join(out, "case.json"), solver=solver, quiet=True, timeout=timeout)
    solver_seconds = time.monotonic() - start
    if result.returncode != 0:
        raise RuntimeError(f"{' '.join(result.args)} failed:\n{result.stdout}\n{result.stderr}")
    if figures:
        quietly(f"postprocess {out}", stages.postprocess, out)
    return out, solver_seconds


def quietly(what: str, stage, *args):
    """stage(*args) with what it prints kept back, as a stage run by make would keep it in its log:
    shown only in the RuntimeError of a stage that fails."""
    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            stage(*args)
    except Exception as error:
        raise RuntimeError(f"{what} failed: {error}\n{said.getvalue()}") from error


def geometry_parameters(out_dir: str) -> dict:
    """geometry.parameters of the case file that made out_dir (case.json `source`)."""
    import json
    with open(os.path.join(out_dir, "case.json"), encoding="utf-8") as stream:
        source = json.load(stream)["source"]
    path = source if os.path.isabs(source) else os.path.join(ROOT, source)
    with open(path, encoding="utf-8") as stream:
        return (yaml.safe_load(stream).get("geometry") or {}).get("parameters") or {}
