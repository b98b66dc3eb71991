"""End to end: the Newton integrators on several MPI ranks (issues 15 and 13).

quasi_static, mixed and implicit solve on their matrix-free path under MPI: CG whose products are
force evaluations with ghosts (ForceOperator::apply_jacobian), every norm and dot product summed in
global dof order (parallel/dof_sums.hpp). On a tiny plate with a hole (cases/plate_with_hole/
mixed.yaml at dx = 4 mm: 321 nodes), run with linear_solver: cg everywhere so that the serial run
takes the same path, the runs on 1, 2 and 3 ranks write byte for byte the serial run's frames,
frames.pvd and history.csv (but for its wall_time column), and so does implicit with the LPS law
on 3 ranks (its J·x exchanges P and δP); a mixed checkpoint written on 2 ranks continues on 3 ranks
and on 1 byte for byte, an implicit one (a_n per node) on 3; linear_solver: direct is refused on
several ranks, and auto takes cg there (run.log says so).
Kept small for a loaded 2-core machine: 4 load steps, a few hundred CG iterations per run; the file
took 14 s (load ~7) to 44 s (with ctest running beside it).
"""
import json
import os
import shutil
import subprocess

import pytest
import yaml

from e2e_support import ROOT, SOLVER, new_case_folder, prepare_stages  # noqa: E402
from test_mpi_checkpoint import assert_same_run, restart, restarted_at_step
from test_mpi_ranks import MPI_ENV, history_without_wall_time, pytestmark, solve  # noqa: F401


@pytest.fixture(scope="module")
def prepared(tmp_path_factory):
    """The mixed plate with a hole, coarse (dx = 4 mm, 321 nodes) and pulled to fracture in 1 ms."""
    work, case_dir = new_case_folder(tmp_path_factory, "mpi_implicit", "plate_with_hole")
    shutil.copy(os.path.join(ROOT, "cases", "plate_with_hole", "plate_with_hole.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "plate_with_hole", "mixed.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    case["geometry"]["parameters"]["lc"] = 4.0e-3
    case["discretization"]["dx"] = 4.0e-3
    case["node_sets"]["left"]["layer"] = 1.2e-2
    case["node_sets"]["right"]["layer"] = 1.2e-2
    case["boundary_conditions"][0]["displacement"]["x"] = [[0.0, 0.0], [1.0e-3, -3.0e-4]]
    case["boundary_conditions"][1]["displacement"]["x"] = [[0.0, 0.0], [1.0e-3, 3.0e-4]]
    case["time"]["end"] = 1.0e-3
    case["quasi_static"] = {"dt_initial": 2.5e-4, "dt_max": 2.5e-4}
    case["output"]["every_time"] = 2.5e-4
    case.pop("figures", None)
    yaml_path = case_dir / "plate_with_hole.yaml"
    yaml_path.write_text(yaml.safe_dump(case))
    out = work / "prepared"
    prepare_stages(yaml_path, case_dir / "plate_with_hole.geo", out)
    return work, out


def copy_case(prepared, name, change):
    work, out = prepared
    target = work / name
    target.mkdir()
    shutil.copy(out / "nodes.vtu", target / "nodes.vtu")
    case = json.loads((out / "case.json").read_text())
    change(case)
    (target / "case.json").write_text(json.dumps(case))
    return target


def quasi_static(case):
    """Quasi-static load steps to 0.2 mm at each end: the hole's bonds break in the last steps."""
    case["time"]["integrator"] = "quasi_static"
    case["quasi_static"]["linear_solver"] = "cg"
    for condition in case["boundary_conditions"]:
        if condition["component"] == 0:
            condition["values"] = [0.0, condition["values"][1] * 2.0 / 3.0]


def mixed(case):
    """Quasi-static load steps until the cracks run at 0.25 ms, then Verlet to 1 ms."""
    case["time"]["integrator"] = "mixed"
    case["quasi_static"]["linear_solver"] = "cg"


def mixed_cut(case):
    """mixed pulled 4× as far over 2 ms: the cracks cut the plate, and 200 explicit steps later the
    load steps return with each half carried by its grip (QuasiStatic::carry_rigidly): the groups'
    displacements reduced over the ranks, the pieces' labels from each rank's components of the bond
    graph joined across the ranks (integrators/load_path.hpp), without the whole bond list."""
    mixed(case)
    case["time"]["end"] = 2.0e-3
    for condition in case["boundary_conditions"]:
        if condition["component"] == 0:
            condition["times"] = [0.0, 2.0e-3]
            condition["values"] = [0.0, condition["values"][1] * 4.0]


def implicit(case):
    """Implicit dynamics (generalized-α) over 20 µs: the ends pulled at 0.3 m/s, no fracture yet."""
    case["time"]["integrator"] = "implicit"
    case["time"]["end"] = 2.0e-5
    case["output"]["every_time"] = 5.0e-6
    case["implicit"]["linear_solver"] = "cg"
    case["implicit"]["dt_initial"] = 2.5e-6


def implicit_lps(case):
    """implicit with the state-based LPS law: its J·x and diagonal blocks exchange P (and δP, γ)."""
    implicit(case)
    for block in case["blocks"]:
        block["model"] = "lps"
        block["poisson_ratio"] = 0.3


CHANGES = {"quasi_static": quasi_static, "mixed": mixed, "mixed_cut": mixed_cut, "implicit": implicit,
           "implicit_lps": implicit_lps}


def run_serially(prepared, changes):
    """Each change's run without mpirun, in folder <name>_serial: {name: folder}."""
    runs = {}
    for name, change in changes.items():
        folder = copy_case(prepared, f"{name}_serial", change)
        result = solve(folder, None)
        assert result.returncode == 0, f"{name}: {result.stderr}"
        runs[name] = folder
    return runs


@pytest.fixture(scope="module")
def serial_runs(prepared):
    return run_serially(prepared, CHANGES)


def broken_bonds(folder):
    history = history_without_wall_time(folder)
    return int(history[-1].split(",")[history[0].split(",").index("broken_bonds")])


@pytest.mark.parametrize("name, ranks", [("quasi_static", 2), ("quasi_static", 3), ("mixed", 1), ("mixed", 2),
                                         ("mixed", 3), ("mixed_cut", 2), ("mixed_cut", 3), ("implicit", 2),
                                         ("implicit_lps", 3)])
def test_runs_on_several_ranks_equal_the_serial_run_byte_for_byte(prepared, serial_runs, name, ranks):
    serial = serial_runs[name]
    run = copy_case(prepared, f"{name}_np{ranks}", CHANGES[name])
    result = solve(run, ranks)
    assert result.returncode == 0, result.stderr
    assert_same_run(serial, run)
    log = (run / "run.log").read_text()
    assert "by matrix-free CG" in log and "(cg, as the case file asks)" in log
    if not name.startswith("implicit"):  # the plate cracked: bonds broke across the ranks too
        assert broken_bonds(run) > 50
    if name.startswith("mixed"):
        assert "quasi-static → explicit" in log
    if ranks > 1:  # the load-path check joins the ranks' components: no rank holds the whole list
        assert "each rank built only the rows of its own nodes" in log, log
    if name == "mixed_cut":
        assert "the cracks have cut the load path between the prescribed motions" in log
        assert "back in load steps: each piece carried by the one grip that holds it is in equilibrium" in log


def written_with_checkpoints(prepared, name, change, every):
    """A run on 2 ranks of `change` that writes a checkpoint every `every` seconds."""
    def with_checkpoints(case):
        change(case)
        case["output"]["restart_every_time"] = every
    written = copy_case(prepared, f"{name}_ckpt_np2", with_checkpoints)
    result = solve(written, 2)
    assert result.returncode == 0, result.stderr
    return written


def restarted(prepared, written, name, ranks):
    folder = prepared[0] / name
    shutil.copytree(written, folder)
    result = restart(folder, ranks)
    assert result.returncode == 0, f"{name}: {result.stderr}"
    return folder


def test_a_checkpoint_written_on_2_ranks_continues_on_3_and_on_1_bitwise(prepared, serial_runs):
    """The mixed run checkpoints every 0.3 ms: in the load steps and in the explicit phase."""
    written = written_with_checkpoints(prepared, "mixed", mixed, 3.0e-4)
    assert_same_run(serial_runs["mixed"], written)  # the checkpoints cost nothing in the results
    for name, ranks in (("mixed_ckpt_np3", 3), ("mixed_ckpt_serial", None)):
        folder = restarted(prepared, written, name, ranks)
        assert restarted_at_step(folder) > 4  # from the last checkpoint (t ≥ 0.9 ms: explicit steps)
        assert_same_run(serial_runs["mixed"], folder)


def test_an_implicit_checkpoint_with_its_accelerations_continues_across_rank_counts(prepared, serial_runs):
    """implicit's checkpoint holds a_n per node: gathered in global order on 2 ranks, read on 3."""
    written = written_with_checkpoints(prepared, "implicit", implicit, 1.0e-5)
    folder = restarted(prepared, written, "implicit_ckpt_np3", 3)
    assert restarted_at_step(folder) > 0
    assert_same_run(serial_runs["implicit"], folder)


@pytest.mark.parametrize("section", ["quasi_static", "implicit"])
def test_direct_is_refused_on_several_ranks_and_auto_takes_cg(prepared, section):
    def direct(case):
        CHANGES[section](case)
        case[section]["linear_solver"] = "direct"
    folder = copy_case(prepared, f"{section}_direct", direct)
    result = solve(folder, 2)
    assert result.returncode != 0
    assert (f"case.json: {section}.linear_solver: direct factorises the whole tangent on one process and is not "
            "decomposed over MPI ranks (here 2)") in result.stderr

    def auto(case):
        CHANGES[section](case)
        case[section]["linear_solver"] = "auto"
        case["time"]["end"] = case["output"]["every_time"]  # one output interval is enough here
    folder = copy_case(prepared, f"{section}_auto", auto)
    result = solve(folder, 2)
    assert result.returncode == 0, result.stderr
    assert ("(cg, auto: decomposed over 2 MPI ranks (a factorisation stays on one process; a problem that fits one "
            "process is usually solved faster by one rank with it))") in (folder / "run.log").read_text()


def quasi_static_auto(case):
    """quasi_static with linear_solver auto: CG on several ranks, CHOLMOD on one (2D, assembled)."""
    quasi_static(case)
    case["quasi_static"]["linear_solver"] = "auto"
    case["output"]["restart_every_time"] = 6.0e-4  # one checkpoint, the first load step past 0.6 ms


def test_a_quasi_static_checkpoint_keeps_its_linear_solver_on_another_rank_count(prepared):
    """Issue 36, item 9: auto's linear solver depends on the rank count, and the checkpoint records
    it. A checkpoint of a 2-rank run (CG) resumed on 1 rank goes on with CG, bitwise the
    uninterrupted 2-rank run (before, it switched to CHOLMOD without a word); a checkpoint of a
    1-rank run (CHOLMOD) resumed on 2 ranks cannot factorise there, and says so once."""
    written = copy_case(prepared, "qs_auto_np2", quasi_static_auto)
    result = solve(written, 2)
    assert result.returncode == 0, result.stderr
    assert "(cg, auto: decomposed over 2 MPI ranks" in (written / "run.log").read_text()
    folder = restarted(prepared, written, "qs_auto_np2_to_serial", None)
    assert restarted_at_step(folder) > 0  # the first step past 0.6 ms, of some 20 (load steps cut as bonds break)
    assert_same_run(written, folder)
    assert ("(cg, as the checkpoint was written; this run alone would take direct, auto: "
            in (folder / "run.log").read_text())

    serial = copy_case(prepared, "qs_auto_serial", quasi_static_auto)
    result = solve(serial, None)
    assert result.returncode == 0, result.stderr
    assert "(direct, auto: " in (serial / "run.log").read_text()
    folder = prepared[0] / "qs_auto_serial_to_np2"
    shutil.copytree(serial, folder)
    result = restart(folder, 2)
    assert result.returncode == 0, result.stderr
    warning = (f"pdsolve: warning: {folder / 'checkpoint.bin'} was written by a run solving with direct, which this "
               "run cannot take (direct factorises the whole tangent on one process, and this run is decomposed "
               "over 2 MPI ranks): it goes on with cg block_jacobi, and its results will not be bitwise those of "
               "the uninterrupted run")
    assert result.stderr.count(warning) == 1, result.stderr
    assert warning in (folder / "run.log").read_text()


def test_an_implicit_checkpoint_of_one_rank_resumed_on_two_drops_its_factor_and_says_so(prepared):
    """implicit with linear_solver auto factorises on one rank; its checkpoint holds where the factor
    was made (the whole model's u). Resumed on 2 ranks, which cannot factorise, the run reads past
    it, goes on with CG and says once that it is not bitwise the uninterrupted run (before: it
    factorised the saved tangent for nothing and went on with CG without a word; quasi_static's
    such restart was refused, 'integrator state of the wrong size')."""
    def implicit_auto(case):
        implicit(case)
        case["implicit"]["linear_solver"] = "auto"
        case["output"]["restart_every_time"] = 1.0e-5
    serial = copy_case(prepared, "implicit_auto_serial", implicit_auto)
    result = solve(serial, None)
    assert result.returncode == 0, result.stderr
    assert "(direct, auto: " in (serial / "run.log").read_text()
    folder = prepared[0] / "implicit_auto_serial_to_np2"
    shutil.copytree(serial, folder)
    result = restart(folder, 2)
    assert result.returncode == 0, result.stderr
    assert restarted_at_step(folder) > 0
    assert result.stderr.count("was written by a run solving with direct, which this run cannot take (direct "
                               "factorises the whole tangent on one process, and this run is decomposed over 2 MPI "
                               "ranks): it goes on with cg block_jacobi") == 1, result.stderr
