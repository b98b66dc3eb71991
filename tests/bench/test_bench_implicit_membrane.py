"""`make bench-implicit`'s membrane problem (bench/implicit_dynamics.py): the lattice and the case it
writes are cases/membrane's (2500 nodes, dx = 1 mm, a clamped layer 3 mm deep, the 6 mm disk moving
at 10 m/s, damping 300 1/s), so that its rows measure that case and not another."""
import json
import os

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from bench import implicit_dynamics  # noqa: E402
from preprocess.node_file import read_node_file  # noqa: E402


def test_membrane_problem_is_cases_membrane_on_its_lattice(tmp_path):
    problem = implicit_dynamics.membrane_problem(str(tmp_path), 1e-3)
    cloud = read_node_file(str(tmp_path / "nodes.vtu"))
    assert problem["nodes"] == len(cloud.volume) == 2500
    x, y = cloud.points[:, 0], cloud.points[:, 1]
    assert np.allclose([x.min(), x.max(), y.min(), y.max()], [0.5e-3, 49.5e-3, 0.5e-3, 49.5e-3])
    # 3 rows of nodes along each side (centres at 0.5, 1.5, 2.5 mm): 50² − 44² clamped
    assert int(cloud.sets["clamped"].sum()) == 2500 - 44 * 44
    # the disk of radius 6 mm about the centre (25, 25) mm: 112 nodes, as `make case=membrane`'s
    # preprocess tags its physical group `centre` (and 564 `clamped`)
    inside = np.hypot(x - 25e-3, y - 25e-3) < 6e-3
    assert int(cloud.sets["centre"].sum()) == int(inside.sum()) == 112
    path = implicit_dynamics.write_case(str(tmp_path), problem, "verlet", {"integrator": "verlet", "dt": "stable",
                                                                           "safety_factor": 0.8}, None)
    with open(path, encoding="utf-8") as stream:
        case = json.load(stream)
    assert case["damping"] == 300.0
    assert case["initial_conditions"] == [{"set": "centre", "kind": "velocity", "component": 2, "value": 10.0}]
    assert case["horizon"] == 3.015 * 1e-3 and case["blocks"][0]["youngs_modulus"] == 3.0e9
    assert case["time"]["end"] == 1e-3 and case["output"]["every_time"] == 1e-3 / 20
