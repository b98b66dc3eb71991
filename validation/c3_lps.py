"""docs/theory.md C3 for LPS in 3D (issue 14): a 108 × 21 × 21 lattice bar in static tension, ν = 0.2,
0.3, 0.45, hhb partial volumes, m = 4, with the energy surface correction and without it. The
interior (2δ from every lateral face, the middle third of the length) must have the axial strain
σ/E and the lateral strain −νσ/E within 2 % with the correction; the uncorrected errors are reported.

The static solve is the gtest LpsTension.BarMeetsC3In3dWithItsInteriorTwoHorizonsFromEveryFace
(solver/tests/materials/test_lps_tension.cpp: CG on the matrix-free J(0)·x, the same helper as the
2D plates of `make test`), run here with PD_LPS_TENSION_VALIDATE=1 because its six solves take
minutes; this module reads the rows it prints. Why this bar and not the 36 × 13² of `make test`:
validation/README.md, "C3 for LPS in 3D: why the lateral strain missed".
"""
from __future__ import annotations

import os
import re
import subprocess

from common.paths import pdsolve

from .common import Check
from .runner import ROOT

TEST = "LpsTension.BarMeetsC3In3dWithItsInteriorTwoHorizonsFromEveryFace"
TOLERANCE = 2.0  # %, docs/theory.md C3 with a surface correction
ROW = re.compile(r"\[ c3 lps   \] (corrected|uncorrected)\s+3d\s+nu=(\S+) .* cg=\s*(\d+)(.*?): "
                 r"axial ([+-]\d+\.\d+) %, lateral ([+-]\d+\.\d+) %")


def tests_binary() -> str:
    """pd_tests beside the solver ($PDSOLVE's folder, else build/solver)."""
    return os.path.join(os.path.dirname(os.path.abspath(pdsolve())), "pd_tests")


def parse(text: str) -> list[dict]:
    """The corrected and uncorrected rows the test printed: analysis ν, CG iterations, errors in %."""
    return [{"which": m.group(1), "nu": float(m.group(2)), "cg": int(m.group(3)), "converged": not m.group(4),
             "axial": float(m.group(5)), "lateral": float(m.group(6))} for m in ROW.finditer(text)]


def checks_from(rows: list[dict], returncode: int, case: str = "c3_lps") -> list[Check]:
    out = []
    for r in rows:
        if r["which"] != "corrected":
            continue
        bare = next((u for u in rows if u["which"] == "uncorrected" and u["nu"] == r["nu"]), None)
        note = (f"uncorrected axial {bare['axial']:+.2f} %, lateral {bare['lateral']:+.2f} %" if bare else "")
        note += f"; CG {r['cg']} iterations{'' if r['converged'] else ' (NOT converged)'}"
        for what in ("axial", "lateral"):
            out.append(Check(case, f"3D bar 108 × 21², ν = {r['nu']:g}, hhb, m = 4, energy correction: interior "
                                   f"{what} strain error [%]", f"0 ± {TOLERANCE:g}", r[what],
                             bool(r["converged"] and abs(r[what]) <= TOLERANCE), note=note))
    if len(out) != 6 or returncode != 0:
        out.append(Check(case, f"{TEST} (6 rows, exit 0)", "passes", f"{len(out)} rows, exit {returncode}", False))
    return out


def validate(report_dir: str) -> list[Check]:
    binary = tests_binary()
    if not os.path.exists(binary):
        raise FileNotFoundError(f"{binary} is missing: build it with `make solver`")
    env = dict(os.environ, PD_LPS_TENSION_VALIDATE="1")
    result = subprocess.run([binary, f"--gtest_filter={TEST}"], cwd=ROOT, env=env, capture_output=True, text=True,
                            timeout=7200)
    os.makedirs(os.path.join(report_dir, "work"), exist_ok=True)
    with open(os.path.join(report_dir, "work", "c3_lps.log"), "w", encoding="utf-8") as stream:
        stream.write(result.stdout + result.stderr)
    return checks_from(parse(result.stdout), result.returncode)
