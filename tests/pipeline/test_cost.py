"""The work plan before a run is spent (issue 17, item 11): nodes, bonds, steps, frames, memory,
disk, time; above an hour (or half the free memory or disk) preprocess stops unless FORCE=1."""
import textwrap

import numpy as np
import pytest
from scipy.spatial import cKDTree

from pipeline.case import CaseError, load_case
from pipeline.cost import BOND_RATE, check_cost, estimate, mean_bonds
from pipeline.stability import BOND_SLACK
from minimal_case import PMMA_PLATE, lattice_cloud

DX = 0.001
CASE = PMMA_PLATE.replace("end: 1.0e-4", "end: {end}") + "output:\n  every_time: {every}\n"


def cloud():
    return lattice_cloud(dx=DX)


def case_of(tmp_path, end, every):
    path = tmp_path / "plate.yaml"
    path.write_text(textwrap.dedent(CASE.format(end=end, every=every)))
    return load_case(str(path))


def test_bonds_are_counted_and_steps_frames_time_follow():
    c = cloud()
    horizon = 3.015 * DX
    brute = sum(int(np.sum(np.linalg.norm(c.points - p, axis=1) <= horizon)) - 1 for p in c.points)
    bonds = mean_bonds(c.points, cKDTree(c.points), horizon, BOND_SLACK) * len(c.points)
    assert bonds == pytest.approx(brute, abs=1e-9)


def test_a_run_of_days_stops_with_what_to_do_unless_forced(tmp_path):
    case = case_of(tmp_path, 10.0, 1.0)
    cost = estimate(case, cloud(), 1.0e6, 1.0e-7)     # 10^8 steps of 10^6 bonds: 10^14 updates
    assert cost["steps"] == 100_000_000 and cost["frames"] == 12
    assert cost["seconds"] == pytest.approx(1e14 / BOND_RATE)
    with pytest.raises(CaseError) as info:
        check_cost(case, cost, str(tmp_path), force=False)
    message = str(info.value)
    assert message.startswith(f"{tmp_path / 'plate.yaml'}:10: work plan: 120 nodes, 1e+06 bonds, 100000000 steps, "
                              "12 frames; about ")
    assert f"it would run about {1e14 / BOND_RATE / 86400:.1f} days (more than 1 h)" in message
    assert "or run it anyway with FORCE=1 (make FORCE=1 case=...)" in message
    line = check_cost(case, cost, str(tmp_path), force=True)
    assert line.startswith("work plan: 120 nodes") and "days at " in line


def test_a_short_run_passes_with_its_plan(tmp_path):
    case = case_of(tmp_path, 1.0e-4, 1.0e-5)
    cost = estimate(case, cloud(), 3000.0, 1.0e-7)
    line = check_cost(case, cost, str(tmp_path), force=False)
    assert line == ("work plan: 120 nodes, 3e+03 bonds, 1000 steps, 12 frames; about 0 MB of memory, 0 MB of disk, "
                    f"0 s at {BOND_RATE:.2g} bond updates/s")


# -- the Newton integrators and the lists that multiply postprocess's work (issue 36, item 12) ----

NEWTON = PMMA_PLATE.replace("end: 1.0e-4", "end: {end}\n  integrator: {integrator}") + "{extra}"


def newton_case(tmp_path, integrator, end=1.0, extra=""):
    path = tmp_path / "plate.yaml"
    path.write_text(NEWTON.format(end=end, integrator=integrator, extra=extra))
    return load_case(str(path))


def test_a_quasi_static_run_counts_its_fewest_load_steps(tmp_path):
    """Before: 'no time estimate' for quasi_static, implicit and mixed, whatever their size."""
    from pipeline.cost import NEWTON_STEP_SECONDS_PER_BOND
    # defaults: dt_initial = end/100 doubling to dt_max = end/10: 0.01, 0.02, 0.04, 0.08, then 9 × 0.1
    cost = estimate(newton_case(tmp_path, "quasi_static"), cloud(), 3000.0, 1.0e-7)
    assert cost["steps"] == 13 and cost["at_least"]
    assert cost["seconds"] == pytest.approx(13 * 3000.0 * NEWTON_STEP_SECONDS_PER_BOND[2])
    line = check_cost(newton_case(tmp_path, "quasi_static"), cost, str(tmp_path), force=False)
    assert line.startswith("work plan: 120 nodes, 3e+03 bonds, at least 13 load steps, ")
    assert line.endswith("at least 0 s at 3.5e-06 s per step and bond (measured on the shipped Newton cases)")


def test_a_quasi_static_run_of_hours_stops_unless_forced(tmp_path):
    case = newton_case(tmp_path, "quasi_static", extra="quasi_static:\n  dt_max: 1.0e-6\n")
    cost = estimate(case, cloud(), 1.0e6, 1.0e-7)      # 10^6 load steps of 10^6 bonds
    assert cost["steps"] == 1_000_000
    with pytest.raises(CaseError) as info:
        check_cost(case, cost, str(tmp_path), force=False)
    message = str(info.value)
    assert message.startswith(f"{tmp_path / 'plate.yaml'}:10: work plan: 120 nodes, 1e+06 bonds, at least 1000000 "
                              "load steps, ")
    assert "it would run at least 40.5 days (more than 1 h)" in message
    assert "allow longer steps (quasi_static.dt_max)" in message and "FORCE=1" in message
    assert check_cost(case, cost, str(tmp_path), force=True).startswith("work plan:")


def test_an_implicit_run_counts_steps_of_its_accuracy(tmp_path):
    """The implicit step: 2 × eq. 2.5 at tol 1e-3 (cases/membrane), longer at a looser tol, at most dt_max."""
    case = newton_case(tmp_path, "implicit", end=1.0e-3)
    cost = estimate(case, cloud(), 1.0e6, 1.0e-7, dt_eq25=1.0e-7)
    assert cost["steps"] == 5000 and not cost["at_least"]         # 1e-3 / (2 × 1e-7)
    with pytest.raises(CaseError, match=r"5000 implicit steps, .* it would run about 4\.9 h \(more than 1 h\)"):
        check_cost(case, cost, str(tmp_path), force=False)
    loose = newton_case(tmp_path, "implicit", end=1.0e-3, extra="implicit:\n  tol: 1.0e-2\n")
    assert estimate(loose, cloud(), 1.0e6, 1.0e-7, dt_eq25=1.0e-7)["steps"] == 1410   # 1e-3 / (2e-7 × 10^0.55)
    capped = newton_case(tmp_path, "implicit", end=1.0e-3, extra="implicit:\n  dt_max: 1.0e-8\n")
    # from time.dt = 1e-9 doubling: 1, 2, 4, 8 ns (15 ns), then (1 ms − 15 ns) / 10 ns
    assert estimate(capped, cloud(), 1.0e6, 1.0e-9, dt_eq25=1.0e-7)["steps"] == 4 + 99_999


def test_mixed_counts_its_start_scheme_as_a_lower_bound(tmp_path):
    case = newton_case(tmp_path, "mixed", extra="quasi_static:\n  dt_initial: 0.1\n  dt_max: 0.1\n")
    cost = estimate(case, cloud(), 3000.0, 1.0e-7)
    assert cost["steps"] == 10 and cost["at_least"]
    assert "at least 10 load steps" in check_cost(case, cost, str(tmp_path), force=False)


def test_run_cost_passes_eq_2_5_to_the_implicit_estimate(tmp_path):
    """The stage's own wiring (pipeline/stages.py run_cost): eq. 2.5 of the cloud sets the implicit step."""
    import math
    from pipeline.resolve import resolve
    from pipeline.stages import run_cost
    from pipeline.solver_physics import physics_of_cloud
    case = newton_case(tmp_path, "implicit", end=1.0e-3)
    resolved = resolve(case, node_sets=[], grid_spacing=DX, nodes_file="nodes.vtu")
    c = cloud()
    dt_eq25 = physics_of_cloud(resolved, c)["stable"]
    assert run_cost(case, resolved, c)["steps"] == math.ceil(1.0e-3 / (2.0 * dt_eq25) - 1e-9)


def test_figures_times_and_frames_are_capped_at_the_yaml_line(tmp_path):
    """90 000 figures.times passed check and postprocess drew maps for minutes."""
    path = tmp_path / "plate.yaml"
    path.write_text(PMMA_PLATE + "figures:\n  times: [" + ", ".join(["1.0e-5"] * 90_000) + "]\n")
    with pytest.raises(CaseError, match=r"plate\.yaml:12: figures\.times: 90000 times; at most 24: each draws a "
                                        r"damage and a displacement map"):
        load_case(str(path))
    path.write_text(PMMA_PLATE + "figures:\n  times: []\n")
    with pytest.raises(CaseError, match=r"plate\.yaml:12: figures\.times: an empty list"):
        load_case(str(path))
    path.write_text(PMMA_PLATE + "output:\n  every_time: 1.0e-9\n")
    with pytest.raises(CaseError, match=r"plate\.yaml:12: output\.every_time: 1e-09 s makes 1e\+05 frames .* at "
                                        r"most 10000 .* use every_time ≥ 1e-08 s"):
        load_case(str(path))
    case = case_of(tmp_path, 1.0e-4, 1.0e-5)
    case["output"]["every_time"], case["output"]["every_steps"] = None, 1
    with pytest.raises(CaseError, match=r"it writes about 100002 frames \(more than 10000"):
        check_cost(case, estimate(case, cloud(), 3000.0, 1.0e-9), str(tmp_path), force=False)
