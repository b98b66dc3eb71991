"""The quasi-static tension problem of `make bench-accuracy` (bench/tension.py): its quick form runs
end to end, and the closing speedup line says what the csv rows say (the mixed row's wall time and
peak error, the cheapest explicit row within 2 % of the reference's peak with the same crack, their
ratio). The measures themselves on made-up curves and rows."""
import csv
import os
import re
import subprocess

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from bench import tension
from common.paths import PYTHON, pdsolve

SOLVER = pdsolve()
LINE = re.compile(r"^speedup tension: mixed ([0-9.]+) s against explicit ([0-9.]+) s \((verlet-alpha[0-9.e+]+), "
                  r"([0-9.e+-]+) m/s\): ([0-9.e+]+)x, peak force ([0-9.e+-]+)$")


def test_peak_is_the_largest_force_before_the_strip_breaks():
    d = np.linspace(0.0, 1.0, 11)
    f = np.array([0, 1, 2, 3, 4, 5, 1, 0.5, 9, 9, 0.0])  # 9: the broken halves ringing, after the drop
    assert tension.peak(d, f) == (5.0, 0.5, 5)


def test_curve_error_is_relative_l2_up_to_the_reference_peak():
    d = np.linspace(0.0, 1.0, 11)
    ref = np.minimum(d, 0.5) * 10.0
    ref[6:] = 0.0                                    # the reference breaks after d = 0.5
    assert tension.curve_error(d, ref, d, ref) == 0.0
    assert tension.curve_error(d, 1.1 * ref, d, ref) == pytest.approx(0.1, rel=1e-12)


def row(scheme, parameter, wall, peak_error, same_crack=True, status="ok"):
    return {"problem": "tension", "scheme": scheme, "parameter": parameter, "wall_time": wall,
            "peak_error": peak_error, "same_crack": same_crack, "status": status}


def test_speedup_line_takes_the_cheapest_explicit_run_as_accurate_as_asked():
    rows = [row("verlet-alpha0", 0.8, 0.1, 0.05),                    # cheaper, 5 % off: not as accurate
            row("verlet-alpha0", 0.4, 0.2, 0.01, same_crack=False),  # crack elsewhere
            row("verlet-alpha1.7e+04", 0.4, 0.3, 0.015),             # the one
            row("verlet-alpha1.75e+04", 0.2, 0.6, 0.0),
            row("quasi_static", 0.2, 0.01, 0.0),
            row("mixed", 0.2, 0.05, 0.004)]
    assert tension.speedup_line(rows, "tension") == ("speedup tension: mixed 0.050 s against explicit 0.300 s "
                                                     "(verlet-alpha1.7e+04, 0.4 m/s): 6x, peak force 4.00e-03")


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    if not os.path.exists(SOLVER):
        pytest.fail(f"{SOLVER} is missing: build it with `make solver`")
    out = tmp_path_factory.mktemp("bench")
    result = subprocess.run([PYTHON, "-m",
                             "bench.accuracy", "--quick", "--problems", "tension", "--solver", SOLVER,
                             "--out", str(out)], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    with open(out / "accuracy.csv", newline="", encoding="utf-8") as stream:
        rows = list(csv.DictReader(stream))
    return result.stdout.splitlines(), rows


def test_quick_tension_ends_with_a_speedup_line_the_rows_bear_out(quick_run):
    lines, rows = quick_run
    assert {r["problem"] for r in rows} == {"tension"}
    schemes = {r["scheme"] for r in rows}
    assert {"verlet-alpha0", "verlet-alpha17500", "quasi_static", "mixed"} <= schemes  # undamped, ζ = 0.1
    assert sum(r["reference"] == "True" for r in rows) == 1
    found = LINE.match(lines[-1])
    assert found, lines[-1]
    mixed_s, explicit_s, scheme, speed, ratio, peak_error = found.groups()
    mixed = next(r for r in rows if r["scheme"] == "mixed")
    assert mixed["status"] == "ok"
    assert float(mixed_s) == pytest.approx(float(mixed["wall_time"]), abs=5e-4)
    assert float(peak_error) == pytest.approx(float(mixed["peak_error"]), rel=1e-2, abs=1e-12)
    accurate = [r for r in rows if r["scheme"].startswith("verlet") and r["status"] == "ok"
                and float(r["peak_error"]) <= 0.02 and r["same_crack"] == "True"]
    cheapest = min(accurate, key=lambda r: float(r["wall_time"]))
    assert (cheapest["scheme"], float(cheapest["parameter"])) == (scheme, pytest.approx(float(speed), rel=1e-6))
    assert float(explicit_s) == pytest.approx(float(cheapest["wall_time"]), abs=5e-4)
    assert float(ratio) == pytest.approx(float(cheapest["wall_time"]) / float(mixed["wall_time"]), rel=6e-3)
    # The reference is an explicit run in the list, exact against itself.
    reference = next(r for r in rows if r["reference"] == "True")
    assert reference["scheme"] == "verlet-alpha17500" and float(reference["peak_error"]) == 0.0
    # Every row's cost in force-evaluation equivalents is at least its force evaluations.
    for r in rows:
        if r["status"] == "ok":
            assert float(r["evaluation_equivalents"]) >= int(r["force_evaluations"])
    assert int(mixed["factorisations"]) > 0
