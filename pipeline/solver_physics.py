"""The physics of a case's set-up, asked of the solver: `pdsolve --physics case.json` run and parsed.

Thesis eq. 2.5's stable step (with the partial-volume rule, contact springs, LPS and the surface
corrections) and each law's micromodulus and critical stretch are computed by pdsolve alone
(solver/src/io/physics_query.hpp), on the model it builds for a run. The Python side used to carry a
second implementation of them, held equal to the solver's by tests; it now asks.

    physics(case_json)              the query on a case.json that exists
    physics_of_cloud(resolved, cloud)
                                    the same before one exists: the pre-processor checks the step
                                    (unit mistakes) and plans the run before it writes anything, so
                                    the resolved case and its node cloud are written into a temporary
                                    folder, asked there, and removed

The solver is the caller's (stages.preprocess(..., solver=...): peridyn's, validation's), else
common.paths.pdsolve(): $PDSOLVE, else the Makefile's build/solver/pdsolve, which the Makefile builds
before preprocess. Without it, or when it refuses the case, SolverError says which solver, what
failed and how to get one.
"""
from __future__ import annotations

import json
import os
import subprocess
import tempfile

from common.paths import pdsolve


class SolverError(RuntimeError):
    """pdsolve is missing, or could not answer the query."""


def physics(case_json: str, *, exact: bool = False, solver: str | None = None) -> dict:
    """`pdsolve --physics case_json` as a dictionary: "stable" (eq. 2.5 before the safety factor,
    None when no node has a bond), "node" (the first node where it is reached, 0-based in node-file
    order, or None), "safety_factor", "blocks" ([{"name", "micromodulus", "critical_stretch"}] in
    block-id order), "surface_correction" ({"method", "bond_factor": [least, largest]}), and with
    `exact` "exact" (2/ω_max)."""
    solver = os.path.abspath(solver or pdsolve())
    command = [solver, "--physics", case_json] + (["--exact"] if exact else [])
    hint = ("build it with `make solver` (make case=... builds it before preprocess), or set PDSOLVE to a "
            "built pdsolve")
    if not os.path.isfile(solver):
        raise SolverError(f"the solver {solver} is missing; the stable time step and the work plan are "
                          f"computed by it: {hint}")
    try:
        result = subprocess.run(command, capture_output=True, text=True)
    except OSError as err:
        raise SolverError(f"the solver {solver} could not be run ({err.strerror}): {hint}") from err
    if result.returncode != 0:
        message = result.stderr.strip() or f"exit status {result.returncode}"
        raise SolverError(f"{' '.join(command)} failed: {message}")
    try:
        return json.loads(result.stdout)
    except ValueError as err:
        raise SolverError(f"{' '.join(command)} printed no JSON (is {solver} a pdsolve with --physics?): "
                          f"{result.stdout.strip()[:200]!r}") from err


def physics_of_cloud(resolved: dict, cloud, *, exact: bool = False, solver: str | None = None,
                     named: str | None = None) -> dict:
    """physics() of the resolved case (its case.json dictionary) on its node cloud, before either is
    written where it belongs: both go to a temporary folder (nodes_file "nodes.vtu", output_dir
    "." there: the query writes nothing), which is removed afterwards. The conditions and the other
    keys that name node sets are left out of that copy: no number of the answer depends on them, and
    a set the solver would refuse is reported by the solver's run as before, not here (nor does a
    cloud without sets, as the tests make, need them). named: the case.json the answer is for, put
    in a message in place of the temporary one."""
    from preprocess.node_file import write_node_file

    physics_only = dict(resolved, nodes_file="nodes.vtu", output_dir=".", boundary_conditions=[],
                        initial_conditions=[], no_fail_sets=[])
    physics_only["output"] = {k: v for k, v in resolved.get("output", {}).items() if k not in ("reactions", "probes")}
    with tempfile.TemporaryDirectory(prefix="pd-physics-") as folder:
        write_node_file(os.path.join(folder, "nodes.vtu"), cloud)
        case_json = os.path.join(folder, "case.json")
        with open(case_json, "w", encoding="utf-8") as stream:
            json.dump(physics_only, stream, indent=1)
        try:
            return physics(case_json, exact=exact, solver=solver)
        except SolverError as err:
            if named is None:
                raise
            message = str(err).replace(case_json, named).replace(os.path.join(folder, "nodes.vtu"),
                                                                  os.path.join(os.path.dirname(named), "nodes.vtu"))
            raise SolverError(message) from None


def stable_step(answer: dict) -> tuple[float, int]:
    """(eq. 2.5's step, the node) of a physics() answer; (inf, -1) when no node has a bond."""
    if answer["stable"] is None:
        return float("inf"), -1
    return float(answer["stable"]), int(answer["node"])


class CaseQuery:
    """physics_of_cloud asked once, when first needed: the pre-processor's checks may stop before
    the step is needed (a horizon below the spacing), and the step check and the work plan share
    one answer."""

    def __init__(self, resolved: dict, cloud, named: str | None = None, solver: str | None = None):
        self._resolved, self._cloud, self._named, self._solver, self._answer = resolved, cloud, named, solver, None

    def answer(self) -> dict:
        if self._answer is None:
            self._answer = physics_of_cloud(self._resolved, self._cloud, named=self._named, solver=self._solver)
        return self._answer

    def stable_step(self) -> tuple[float, int]:
        return stable_step(self.answer())
