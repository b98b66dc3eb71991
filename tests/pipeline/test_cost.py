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
