"""Set-up checks once the nodes exist (issue 17, items 10 and 12): conditions that overlap through
shared nodes, a horizon of about one spacing, a safety factor above 1; each names its .yaml line."""
import textwrap

import numpy as np
import pytest

from pipeline.case import CaseError, load_case
from pipeline.conditions import check_condition_overlaps
from pipeline.resolve import resolve
from pipeline.stability import check_discretized_case
from minimal_case import PMMA_PLATE, lattice_cloud

CASE = PMMA_PLATE
DX = 0.001


def cloud():
    c = lattice_cloud(dx=DX)
    pts = c.points
    c.sets = {"left": pts[:, 0] < 2.5 * DX, "bottom": pts[:, 1] < 2.5 * DX, "plate": np.ones(len(pts), bool)}
    return c


def load(tmp_path, text, time_keys=""):
    """The case with more keys of time: and then the sections of `text` (dedented)."""
    path = tmp_path / "plate.yaml"
    path.write_text(CASE + time_keys + textwrap.dedent(text))
    return load_case(str(path))


def warnings_of(tmp_path, text, time_keys=""):
    case = load(tmp_path, text, time_keys)
    c = cloud()
    resolved = resolve(case, node_sets=list(c.sets), grid_spacing=DX, nodes_file="nodes.vtu")
    return check_condition_overlaps(case, c.sets) + check_discretized_case(case, resolved, c)


def test_a_body_wide_condition_overriding_a_clamp_is_an_error(tmp_path):
    case = load(tmp_path, """\
        boundary_conditions:
          - {set: left, displacement: {x: 0.0, y: 0.0}}
          - {set: plate, velocity: {x: 1.0}}
        """)
    with pytest.raises(CaseError) as info:
        check_condition_overlaps(case, cloud().sets)
    assert ("plate.yaml:13: boundary_conditions[1].velocity.x: set 'plate' shares 30 node(s) with set 'left', "
            "whose component x is given another displacement by boundary_conditions[0] (line 12)") in str(info.value)


def test_a_corner_held_the_same_way_by_two_edges_is_fine(tmp_path):
    case = load(tmp_path, """\
        boundary_conditions:
          - {set: left, displacement: {x: 0.0, y: 0.0}}
          - {set: bottom, displacement: {y: 0.0}}
        """)
    assert check_condition_overlaps(case, cloud().sets) == []


def test_an_initial_velocity_that_every_node_ignores_is_a_warning(tmp_path):
    case = load(tmp_path, """\
        boundary_conditions:
          - {set: plate, displacement: {z: 0.0}}
        initial_conditions:
          - {set: left, velocity: {z: 3.0}}
        """)
    warnings = check_condition_overlaps(case, cloud().sets)
    assert warnings == [f"{case['_path']}:14: initial_conditions[0].velocity.z: all 30 node(s) of set 'left' are "
                        "in set 'plate', whose z is prescribed (displacement, boundary_conditions[0]): the "
                        "initial velocity is ignored; remove it or prescribe the motion instead"]


def test_a_body_moving_with_its_edge_held_is_no_mistake(tmp_path):
    """cases/drum: the membrane gets a velocity, its clamped edge keeps velocity 0."""
    case = load(tmp_path, """\
        boundary_conditions:
          - {set: left, velocity: {z: 0.0}}
        initial_conditions:
          - {set: plate, velocity: {z: 3.0}}
        """)
    assert check_condition_overlaps(case, cloud().sets) == []


def with_horizon(tmp_path, line):
    """The test's plate with `line` added under dx: (path, case, cloud, resolved case.json)."""
    path = tmp_path / "plate.yaml"
    path.write_text(CASE.replace("  dx: 0.001\n", f"  dx: 0.001\n  {line}\n"))
    case = load_case(str(path))
    c = cloud()
    return path, case, c, resolve(case, node_sets=list(c.sets), grid_spacing=DX, nodes_file="nodes.vtu")


def test_a_horizon_of_one_spacing_stops_the_run_with_the_bond_count(tmp_path, monkeypatch):
    path, case, c, resolved = with_horizon(tmp_path, "horizon_factor: 1.0")
    # at δ = dx: 80 interior nodes have 4 bonds, 36 edge nodes 3, the 4 corners 2; 120 nodes
    mean = (4 * 10 * 8 + 3 * 2 * (10 + 8) + 2 * 4) / 120
    message = (f"{path}:5: discretization.horizon_factor: the horizon 0.001 m is 1 × the node spacing 0.001 m: "
               f"{mean:.3g} bonds per node on average; the peridynamic model needs a horizon of about "
               "3 × the spacing (thesis §2.1): use horizon_factor: 3.015")
    monkeypatch.delenv("FORCE", raising=False)
    with pytest.raises(CaseError) as error:
        check_discretized_case(case, resolved, c)
    assert str(error.value) == message + "; FORCE=1 (make FORCE=1 case=...) runs it anyway"
    monkeypatch.setenv("FORCE", "1")                  # a warning then, and the run goes on
    [warning] = [w for w in check_discretized_case(case, resolved, c) if "horizon" in w]
    assert warning == message + " (run anyway: FORCE=1)"


def test_a_horizon_in_metres_left_behind_by_a_coarser_dx_names_the_key_to_change(tmp_path, monkeypatch):
    """Issue 39, item 7: `horizon` fixed in metres, dx coarsened alone: δ = 1 dx ran after a warning."""
    _, case, c, resolved = with_horizon(tmp_path, "horizon: 0.0015")
    monkeypatch.delenv("FORCE", raising=False)
    with pytest.raises(CaseError, match=r"plate.yaml:5: discretization.horizon: the horizon 0.0015 m is 1.5 × the node "
                                        r"spacing 0.001 m: .* discretization.horizon is fixed in metres, so it did not "
                                        r"follow dx: remove it and let horizon_factor \(3.015 by default\) set "
                                        r"δ = 3.015 dx = 0.003015 m, or give a horizon ≥ 0.002 m; FORCE=1"):
        check_discretized_case(case, resolved, c)


@pytest.mark.parametrize("factor, rule, expected", [
    (1.5, "stable", "1.5 > 1 makes the step"),
    (1.5, "exact", "1.5 > 1 with time.dt: exact makes the step larger than the exact stability limit"),
])
def test_a_safety_factor_above_one_is_warned_about(tmp_path, factor, rule, expected):
    warnings = warnings_of(tmp_path, "", f"  dt: {rule}\n  safety_factor: {factor}\n")
    [warning] = [w for w in warnings if "safety_factor" in w]
    assert warning.startswith(f"{tmp_path / 'plate.yaml'}:12: time.safety_factor: {expected}"), warning


def test_the_default_case_has_no_warning(tmp_path):
    assert warnings_of(tmp_path, "") == []
