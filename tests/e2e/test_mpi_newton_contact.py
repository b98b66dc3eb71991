"""End to end: contact inside the Newton solves on several MPI ranks (issue 15).

Under MPI quasi_static, mixed and implicit solve by matrix-free CG whose products are force
evaluations with ghosts; with contact, the product and the block-Jacobi blocks hold the contact's
linearised force (forces/contact_on_piece: the contact ghosts' u and δu from their owners). The scene:
the disk above a clamped plate of cases/impact, coarse (dx = 0.5 mm: 552 nodes, a 2.5 mm gap between
the nearest nodes), the disk driven down as a whole by a displacement condition until it presses on
the plate (the contact distance is 1.35 dx = 0.675 mm):
- mixed: 8 quasi-static load steps of 0.25 ms, the disk pressing from the fourth on (24 CG solves);
- implicit: 2 µs of generalized-α, the disk pressing from 0.1 µs on (about 160 steps).
Both with linear_solver: cg, so that the serial run takes the same path. The runs on 2 and 3 ranks
(and implicit on 2 ranks × 2 threads) write byte for byte the serial run's frames, frames.pvd and
history.csv (but for its wall_time column; contact_energy included).
Measured: the file took 12 s on the shared 2-core machine at load 7 and 31 s in a busier sitting
(each run 1–2 s; the solves themselves take under 1 s of CPU).
"""
import os
import shutil

import pytest
import yaml

from e2e_support import ROOT, new_case_folder, prepare_stages  # noqa: E402
from test_mpi_checkpoint import assert_same_run
from test_mpi_implicit import copy_case, run_serially
from test_mpi_ranks import history_without_wall_time, pytestmark, solve  # noqa: F401

# y of the disk's lowest node minus that of the plate's highest at dx = 0.5 mm (the lattice's rows).
NODE_GAP = 2.5e-3
CONTACT_DISTANCE = 1.35 * 5.0e-4


@pytest.fixture(scope="module")
def prepared(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "mpi_newton_contact", "impact")
    shutil.copy(os.path.join(ROOT, "cases", "impact", "impact.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "impact", "impact.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    case["discretization"]["dx"] = 5.0e-4
    case["geometry"]["parameters"].update({"gap": 2.0e-3, "lc": 0.004})  # wider than the horizon 1.5 mm
    case["node_sets"] = {"left": {"layer": 1.6e-3}, "right": {"layer": 1.6e-3}}
    case.pop("initial_conditions")
    case["boundary_conditions"].append({"set": "projectile", "displacement": {"x": 0.0, "y": 0.0}})
    case["time"] = {"end": 2.0e-3, "integrator": "mixed", "dt": "stable"}
    case["quasi_static"] = {"dt_initial": 2.5e-4, "dt_max": 2.5e-4, "linear_solver": "cg"}
    case["implicit"] = {"dt_initial": 2.5e-7, "linear_solver": "cg"}
    case["output"] = {"every_time": 5.0e-4}
    case.pop("figures", None)
    yaml_path = case_dir / "impact.yaml"
    yaml_path.write_text(yaml.safe_dump(case))
    out = work / "prepared"
    prepare_stages(yaml_path, case_dir / "impact.geo", out)
    return work, out


def drive_disk(case, times, values):
    """The disk's y displacement table (the last condition)."""
    condition = case["boundary_conditions"][-1]
    assert condition["set"] == "projectile" and condition["component"] == 1
    condition["times"], condition["values"] = times, values


def mixed(case):
    """Down 1.9 mm in 1 ms (0.075 mm into the contact distance), then 0.05 mm more by 2 ms."""
    drive_disk(case, [0.0, 1.0e-3, 2.0e-3], [0.0, -1.90e-3, -1.95e-3])


def implicit(case):
    """From 1 µm outside the contact distance, 20 µm down in 2 µs."""
    case["time"]["integrator"] = "implicit"
    case["time"]["end"] = 2.0e-6
    case["output"]["every_time"] = 1.0e-6
    start = CONTACT_DISTANCE + 1.0e-6 - NODE_GAP
    drive_disk(case, [0.0, 2.0e-6], [start, start - 2.0e-5])


CHANGES = {"mixed": mixed, "implicit": implicit}


def column(folder, name):
    history = history_without_wall_time(folder)
    at = history[0].split(",").index(name)
    return [float(line.split(",")[at]) for line in history[1:]]


@pytest.fixture(scope="module")
def serial_runs(prepared):
    return run_serially(prepared, CHANGES)


def test_the_disk_presses_on_the_plate_inside_the_newton_solves(serial_runs):
    """What the comparison is worth: contact acts during CG solves (its energy grows) in both runs."""
    for name, folder in serial_runs.items():
        energy = column(folder, "contact_energy")
        assert energy[0] == 0.0 and energy[-1] > 0.0, name
        assert sum(e > 0.0 for e in energy) >= 2, name
        log = (folder / "run.log").read_text()
        assert "by matrix-free CG" in log and "(cg, as the case file asks)" in log
        solves = int(log.split(" CG solves with ")[0].rsplit(" ", 1)[1])
        assert solves > 10, log


@pytest.mark.parametrize("name, ranks, threads", [("mixed", 2, 1), ("mixed", 3, 1), ("implicit", 2, 1),
                                                  ("implicit", 3, 1), ("implicit", 2, 2)])
def test_contact_in_newton_solves_on_ranks_equals_the_serial_run_byte_for_byte(prepared, serial_runs, name, ranks,
                                                                              threads):
    run = copy_case(prepared, f"{name}_np{ranks}t{threads}", CHANGES[name])
    result = solve(run, ranks, threads)
    assert result.returncode == 0, result.stderr
    assert_same_run(serial_runs[name], run)
    assert f"decomposed over {ranks} MPI ranks" in (run / "run.log").read_text()
