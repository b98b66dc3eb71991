"""validation/c3_lps.py reads the rows of the C3 gtest (the 3D LPS bar, run by `make validate` only):
parsed from the lines the test prints, a row per ν and strain, failing beyond 2 % or when CG did not
converge or rows are missing. No solve here (the solve takes minutes)."""
from validation import c3_lps

LINES = """\
[ c3 lps   ] corrected              3d           nu=0.20 m=4.015 w=one pv=hhb load=4 L=108 W=21 corr=energy cg=  110: axial +0.30 %, lateral -0.36 %
[ c3 lps   ] uncorrected            3d           nu=0.20 m=4.015 w=one pv=hhb load=4 L=108 W=21 corr=none   cg=  112: axial -7.96 %, lateral -0.84 %
[ c3 lps   ] bulk lattice           3d           nu=0.20 m=4.015 beta=1.0000 gamma=1.0000: axial +0.01 %, lateral -0.04 %; C3 (2 %) with the correction: axial met, lateral met
[ c3 lps   ] corrected              3d           nu=0.30 m=4.015 w=one pv=hhb load=4 L=108 W=21 corr=energy cg=  113: axial +0.38 %, lateral +2.07 %
[ c3 lps   ] uncorrected            3d           nu=0.30 m=4.015 w=one pv=hhb load=4 L=108 W=21 corr=none   cg=  112: axial -8.77 %, lateral +0.39 %
[ c3 lps   ] corrected              3d           nu=0.45 m=4.015 w=one pv=hhb load=4 L=108 W=21 corr=energy cg=20000 (not converged): axial +0.42 %, lateral +0.78 %
"""


def test_rows_are_parsed_and_judged():
    rows = c3_lps.parse(LINES)
    assert [(r["which"], r["nu"]) for r in rows] == [("corrected", 0.2), ("uncorrected", 0.2), ("corrected", 0.3),
                                                   ("uncorrected", 0.3), ("corrected", 0.45)]
    checks = c3_lps.checks_from(rows, 0)
    assert [c.passed for c in checks] == [True, True, True, False, False, False]  # 2.07 % > 2 %; ν = 0.45 not converged
    assert checks[0].got == 0.30 and checks[1].got == -0.36
    assert "uncorrected axial -7.96 %, lateral -0.84 %" in checks[0].note


def test_missing_rows_or_a_failed_test_fail_the_check():
    rows = [r for r in c3_lps.parse(LINES) if r["nu"] == 0.2]
    assert not c3_lps.checks_from(rows, 0)[-1].passed  # 2 rows of 6
    full = c3_lps.parse(LINES.replace("cg=20000 (not converged)", "cg=  182"))
    full.append(dict(full[-1], nu=0.45, which="uncorrected"))
    assert len(c3_lps.checks_from(full, 0)) == 6
    assert not c3_lps.checks_from(full, 1)[-1].passed
