"""The logic of bench/quasi_static_cases.py (traction and plate_with_hole in make bench-accuracy) on
made-up data: where the reference search stops, which explicit run is mixed's rival, the speedup
line, the crack position of two symmetric cracks, and the count of where a mixed run's time goes.
One quick end-to-end run of traction at dx × 8 (about 10 s), and again reusing its explicit rows
(--reuse-explicit) and its explicit rows alone (--explicit-only): some 25 s in all at load ~7; the
full benchmark takes minutes."""
import math
import os
import re

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from bench import quasi_static_cases as qs
from common.paths import PYTHON, pdsolve


def test_reference_search_stops_at_the_first_halving_within_half_a_percent():
    # 0.6 %, then 0.4 %: the third rate is the reference (index 2), not the fourth.
    peaks = [100.0, 100.0 * 1.006, 100.0 * 1.006 * 1.004, 100.0 * 1.006 * 1.004 * 1.001]
    assert qs.reference_search(peaks) == 2
    assert qs.reference_search(peaks[:2]) is None            # 0.6 %: not converged yet
    assert qs.reference_search([150.0]) is None              # one run is no search


def row(scheme, parameter, wall, peak_error, same_crack=True, status="ok", problem="traction", cpu=None):
    return {"problem": problem, "scheme": scheme, "parameter": parameter, "wall_time": wall,
            "cpu_time": wall if cpu is None else cpu,
            "peak_error": peak_error, "same_crack": same_crack, "status": status}


def test_rival_is_the_cheapest_explicit_run_by_cpu_time_within_two_percent_and_the_same_crack():
    rows = [row("verlet-alpha0", 0.5, 1.0, 0.021),                  # cheapest, 2.1 % off
            row("verlet-alpha0", 0.25, 2.0, 0.001, same_crack=False),
            row("verlet-alpha8730", 0.25, 3.0, 0.019),               # the one
            row("verlet-alpha8730", 0.125, 2.5, 0.0, status="failed (1: x)"),
            row("verlet-alpha8730", 0.0625, 6.0, 0.0),
            row("verlet-alpha0", 0.5, 0.1, 0.0, problem="plate_with_hole"),   # another problem
            row("mixed", 0.05, 0.5, 0.0), row("quasi_static", 0.0, 0.2, 0.0)]
    chosen = qs.rival(rows, "traction")
    assert (chosen["scheme"], chosen["parameter"]) == ("verlet-alpha8730", 0.25)
    assert qs.rival([r for r in rows if r is not chosen and r["wall_time"] != 6.0], "traction") is None
    # Ranked by CPU time: a run whose wall time a loaded machine stretched is still the cheapest.
    rows.append(row("verlet-alpha0", 0.25, 9.0, 0.01, cpu=2.9))
    assert qs.rival(rows, "traction")["wall_time"] == 9.0


def test_speedup_line_has_the_issue_format():
    explicit = row("verlet-alpha8730", 0.25, 23.07, 0.01)
    line = qs.speedup_line("traction", 29.96, explicit, 23.07, 0.0123)
    assert line == ("speedup traction: mixed 29.960 s against explicit 23.070 s (verlet-alpha8730, 0.25 m/s): "
                    "0.77x, peak force 1.23e-02")
    assert re.match(r"^speedup \w+: mixed [0-9.]+ s against explicit [0-9.]+ s \([\w.+-]+, [0-9.e+-]+ m/s\): "
                    r"[0-9.e+]+x, peak force [0-9.e+-]+$", line)
    assert qs.speedup_line("traction", 29.96, explicit, 23.07, 0.0123, mixed_same_crack=False) == line + ", crack elsewhere"
    assert qs.speedup_line("plate_with_hole", 2.0, None, math.nan, 0.03) == \
        "speedup plate_with_hole: mixed 2.000 s against no explicit run as accurate, peak force 3.00e-02"


def test_crack_position_places_each_of_two_symmetric_cracks_in_its_half():
    x = np.arange(0.0, 0.121, 0.001)
    damage = np.zeros_like(x)
    damage[[52, 53, 54]] = [0.5, 0.9, 0.5]     # the left crack around 53 mm
    damage[[66, 67, 68]] = [0.5, 0.9, 0.31]    # the right one around 67 mm
    damage[10] = 0.29                           # below the damage threshold: not a crack
    left, right = qs.crack_positions(x, damage, middle=0.06)
    assert left == pytest.approx(0.053) and right == pytest.approx(0.067)
    # One half unbroken: not the same crack as the reference's pair, however close the other is.
    only_left = qs.crack_positions(x, np.where(x < 0.06, damage, 0.0), middle=0.06)
    assert math.isnan(only_left[1])
    assert not qs.same_crack(only_left, (left, right), 0.002)
    assert qs.same_crack((0.0545, 0.0655), (left, right), 0.002)      # each within 2 dx
    assert not qs.same_crack((0.0555, 0.067), (left, right), 0.002)   # 2.5 mm off on the left


def test_where_time_goes_counts_static_and_explicit_steps_from_the_history():
    h = {"step": np.array([0, 1, 2, 3, 4, 5, 6.0]), "time": np.linspace(0.0, 6.0, 7),
         "mode": np.array([1, 1, 1, 1, 0, 0, 0.0]), "iterations": np.array([0, 4, 5, 9, 1, 1, 1.0]),
         "wall_time": np.array([0.0, 1.0, 2.0, 4.0, 4.1, 4.2, 4.3])}
    assert qs.where_time_goes(h) == pytest.approx({"static_steps": 3, "newton_iterations": 18, "explicit_steps": 3, "implicit_steps": 0,
                                                   "static_wall": 4.0, "explicit_wall": 0.3})


def test_grip_displacement_of_a_ramped_velocity_and_of_a_table():
    ramped = {"boundary_conditions": [{"set": "right", "kind": "velocity", "component": 0, "times": [0.0, 2.0],
                                       "values": [0.0, 1.0]}]}
    # v t²/(2 t_r) during the ramp, v (t − t_r/2) after it
    assert qs.grip_displacement(ramped, np.array([1.0, 2.0, 5.0])) == pytest.approx([0.25, 1.0, 4.0])
    table = {"boundary_conditions": [{"set": "right", "kind": "displacement", "component": 0, "times": [0.0, 4.0],
                                      "values": [0.0, 2.0]}]}
    assert qs.grip_displacement(table, np.array([1.0, 4.0])) == pytest.approx([0.5, 2.0])


def test_quick_traction_runs_end_to_end_and_its_speedup_line_matches_the_rows(tmp_path):
    """`--quick --problems traction` (dx × 8, 488 nodes; some 10 s): the rows, the reference found,
    and the last line the issue's speedup line for the mixed row in the csv."""
    import csv
    import subprocess

    solver = pdsolve()
    if not os.path.exists(solver):
        pytest.fail(f"{solver} is missing: build it with `make solver`")
    result = subprocess.run([PYTHON, "-m", "bench.accuracy", "--quick", "--problems", "traction",
                             "--solver", solver, "--out", str(tmp_path)], cwd=ROOT, capture_output=True, text=True,
                            timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    with open(tmp_path / "accuracy.csv", newline="", encoding="utf-8") as stream:
        rows = list(csv.DictReader(stream))
    assert {r["scheme"] for r in rows} >= {"verlet-alpha0", "quasi_static", "mixed"}
    assert sum(r["reference"] == "True" for r in rows) == 1
    mixed = next(r for r in rows if r["scheme"] == "mixed")
    assert mixed["status"] == "ok" and int(mixed["static_steps"]) > 0
    found = re.match(r"^speedup traction: mixed ([0-9.]+) s against explicit ([0-9.]+) s \((verlet-alpha[0-9.e+]+), "
                     r"([0-9.e+-]+) m/s\): ([0-9.e+]+)x, peak force ([0-9.e+-]+)(, crack elsewhere)?$",
                     result.stdout.splitlines()[-1])
    assert found, result.stdout.splitlines()[-1]
    assert float(found.group(6)) == pytest.approx(float(mixed["peak_error"]), rel=1e-2)
    assert float(found.group(5)) == pytest.approx(float(found.group(2)) / float(found.group(1)), rel=3e-2)
    assert any(r["scheme"] == found.group(3) and float(r["parameter"]) == float(found.group(4))
               and float(r["peak_error"]) <= 0.02 and r["same_crack"] == "True" for r in rows)

    # --reuse-explicit the folder just written: every explicit row taken (same inputs, same solver),
    # mixed, quasi_static and the paired reruns run again, the rival rerun in the new folder.
    again = tmp_path / "again"
    second = subprocess.run([PYTHON, "-m", "bench.accuracy", "--quick", "--problems", "traction",
                             "--solver", solver, "--out", str(again), "--reuse-explicit", str(tmp_path)], cwd=ROOT,
                            capture_output=True, text=True, timeout=600)
    assert second.returncode == 0, second.stdout + second.stderr
    with open(again / "accuracy.csv", newline="", encoding="utf-8") as stream:
        rows2 = list(csv.DictReader(stream))
    explicit = [r for r in rows if r["scheme"].startswith("verlet")]
    explicit2 = [r for r in rows2 if r["scheme"].startswith("verlet")]
    assert [(r["scheme"], r["parameter"], r["steps"], r["cpu_time"], r["peak_force"], r["run_dir"]) for r in explicit] \
        == [(r["scheme"], r["parameter"], r["steps"], r["cpu_time"], r["peak_force"], r["run_dir"]) for r in explicit2]
    assert all(r["explicit_source"] == f"reused from {r['run_dir']}" for r in explicit2)
    assert f"explicit runs: {len(explicit2)} taken from {tmp_path} (same solver file), 0 run here" in second.stdout
    mixed2 = next(r for r in rows2 if r["scheme"] == "mixed")
    assert mixed2["run_dir"] == str(again / "traction" / "mixed") and mixed2["steps"] == mixed["steps"]
    assert (again / "traction" / f"verlet-alpha{found.group(3)[len('verlet-alpha'):]}-v{found.group(4)}"
            / "run.log").exists()                                            # the rival's paired reruns
    assert re.match(r"^speedup traction: mixed [0-9.]+ s against explicit", second.stdout.splitlines()[-1])

    # --explicit-only: the explicit rows alone (here all reused again), no mixed, no speedup line.
    only = subprocess.run([PYTHON, "-m", "bench.accuracy", "--quick", "--problems", "traction",
                           "--solver", solver, "--out", str(tmp_path / "only"), "--reuse-explicit", str(tmp_path),
                           "--explicit-only"], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert only.returncode == 0, only.stdout + only.stderr
    with open(tmp_path / "only" / "accuracy.csv", newline="", encoding="utf-8") as stream:
        assert sorted(r["scheme"] for r in csv.DictReader(stream)) == sorted(r["scheme"] for r in explicit)
    assert only.stdout.splitlines()[-1] == "traction: explicit rows only (--explicit-only): no mixed run, no speedup"
