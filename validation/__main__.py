"""`make validate`: run the full cases (through make, so only stale stages rerun), check each one
and write out/validate/report.md (case, quantity, expected, got, pass) and one PNG per case.

    /usr/bin/python3 -m validation [CASE ...]     (default: every case with checks)
Exit status 1 if any check fails.
"""
from __future__ import annotations

import functools
import os
import subprocess
import sys
import time

from common.output_lock import exit_code, output_lock
from common.paths import given_pdsolve

from . import branching, c3_lps, convergence, drum, plate_with_hole, static, three_point_bending, traction, wave, wave_lps
from .figures import FIGURES
from .runner import ROOT

CHECKS = {"plate_with_hole": plate_with_hole.checks, "traction": traction.checks, "branching": branching.checks,
          "branching-lps": functools.partial(branching.checks, case="branching-lps"), "drum": drum.checks,
          "three_point_bending": three_point_bending.checks}
# Checks of a case's variant: name -> (case, config), run by `make case=CASE config=CONFIG` into out/NAME/.
CONFIGS = {"branching-lps": ("branching", "lps")}
# Checks that run their own small models (validation/models/) into out/validate/work/<name>/ and
# draw their own PNG: validate(report_dir) -> rows.
MODEL_CHECKS = {"drum_convergence": drum.validate_convergence, "wave": wave.validate, "wave_lps": wave_lps.validate,
                "static": static.validate, "c3_lps": c3_lps.validate}


def main(argv: list[str]) -> int:
    # One writer per output folder, the lock make and peridyn take too (common/output_lock.py); the
    # cases' own folders are locked by the make that runs each.
    with output_lock(os.path.join(ROOT, "out", "validate"), "make validate"):
        return validate(argv)


def validate(argv: list[str]) -> int:
    """main()'s runs and checks, with out/validate/ locked."""
    cases = argv or list(CHECKS) + list(MODEL_CHECKS)
    begin = time.monotonic()
    report_dir = os.path.join(ROOT, "out", "validate")
    os.makedirs(report_dir, exist_ok=True)
    lines = ["# Validation report", "",
             "Written by `make validate` (validation/__main__.py) from the full runs in out/<case>/.", "",
             "| case | quantity | expected | got | pass |", "|---|---|---|---|---|"]
    notes, failed = [], 0
    for case in cases:
        start = time.monotonic()
        if case in MODEL_CHECKS:
            try:
                rows = MODEL_CHECKS[case](report_dir)
            except Exception as error:  # a failed run is a failed check, the others still run
                lines.append(f"| {case} | the runs | succeed | {type(error).__name__}: "
                             f"{str(error).splitlines()[0][:200] if str(error) else ''} | **NO** |")
                failed += 1
                continue
            for row in rows:
                lines.append(row.row())
                failed += not row.passed
                if row.note:
                    notes.append(f"- {case}, {row.quantity}: {row.note}")
            notes.append(f"- {case}: runs and checks {time.monotonic() - start:.0f} s")
            continue
        # $PDSOLVE (a solver built elsewhere) is handed to make as SOLVER, as runner.py does.
        # (-o: make must not try to rebuild a solver built elsewhere; it also means that a case
        # already solved is not solved again when that solver changes: clean out/<case> first.
        # `make validate` leaves PDSOLVE unset, so its cases follow build/solver like `make case=X`.)
        given = given_pdsolve()
        solver = [f"SOLVER={given}", "-o", given] if given else []
        target = [f"case={CONFIGS[case][0]}", f"config={CONFIGS[case][1]}"] if case in CONFIGS else [f"case={case}"]
        make = subprocess.run(["make", "--no-print-directory", *target, *solver], cwd=ROOT)
        if make.returncode != 0:
            lines.append(f"| {case} | the run | `make {' '.join(target)}` succeeds | exit {make.returncode} | **NO** |")
            failed += 1
            continue
        out = os.path.join(ROOT, "out", case)
        for row in CHECKS[case](out):
            lines.append(row.row())
            failed += not row.passed
            if row.note:
                notes.append(f"- {case}, {row.quantity}: {row.note}")
        FIGURES[CONFIGS[case][0] if case in CONFIGS else case](out, os.path.join(report_dir, f"{case}.png"))
        with open(os.path.join(out, "run.log"), encoding="utf-8") as stream:
            done = [l for l in stream if l.startswith(("done", "stopped"))]
        notes.append(f"- {case}: {done[-1].strip() if done else 'no solver summary'} "
                     f"(make and checks: {time.monotonic() - start:.0f} s)")
    if {"wave", "static", "drum_convergence"} & set(cases):
        convergence.figure(getattr(static.validate, "result", None), getattr(wave.validate, "result", None),
                           os.path.join(report_dir, "convergence.png"),
                           getattr(drum.validate_convergence, "result", None))
    notes.append(f"- total `make validate` time: {time.monotonic() - begin:.0f} s")
    lines += ["", "## Notes", ""] + notes + [""]
    with open(os.path.join(report_dir, "report.md"), "w", encoding="utf-8") as stream:
        stream.write("\n".join(lines))
    print("\n".join(lines))
    print(f"validation: {failed} failed check(s); report in out/validate/report.md")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(exit_code(lambda: main(sys.argv[1:])))
