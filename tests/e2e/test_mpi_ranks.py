"""End to end: pdsolve on 1, 2 and 3 MPI ranks (issue 15) writes byte for byte the frames,
frames.pvd and history.csv (but for its wall_time column) of the serial run.

A coarse, short copy of cases/plate_with_hole (1234 nodes, pulled faster so that it cracks within
300 steps) goes through mesh and preprocess as the Makefile calls them; pdsolve runs without mpirun,
then under `mpiexec --oversubscribe -np R` for R = 1, 2, 3 with one thread per rank and for R = 2
with two. The same holds for the plate with body forces and indenters (a disk pressing its top
edge, a plane pushing its left grip; their reactions in history.csv are sums over the nodes inside)
for the plate of LPS, the state-based law (with the energy surface correction too), for the
adaptive integrator (the Newton integrators: test_mpi_implicit.py), and for dt: exact and a fixed dt
above eq. 2.5, whose exact limit the ranks compute on their pieces. What is not decomposed yet is refused on several
ranks before any output.
"""
import json
import os
import re
import shutil
import subprocess

import numpy as np
import pytest
import yaml

from e2e_support import ROOT, SOLVER, new_case_folder, prepare_stages  # noqa: E402

MPIEXEC = shutil.which("mpiexec")
# The CI runs as root, which OpenMPI refuses unless told that it is meant. OMP_WAIT_POLICY=PASSIVE
# as for the ctest mpi_ranks tests: 2 ranks × 2 threads (np2t2) or 3 ranks on 2 cores, and a thread
# waiting at a barrier would spin on the core a rank needs (no bit changes with the wait policy).
MPI_ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMP_WAIT_POLICY="PASSIVE")


def built_with_mpi():
    if not os.path.exists(SOLVER):
        return False
    version = subprocess.run([SOLVER, "--version"], capture_output=True, text=True).stdout
    return "MPI: on" in version


pytestmark = pytest.mark.skipif(MPIEXEC is None or not built_with_mpi(),
                                reason="pdsolve built without MPI (PD_MPI off) or no mpiexec: "
                                       "install libopenmpi-dev openmpi-bin (pipeline/install-deps.sh)")


@pytest.fixture(scope="module")
def prepared(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "mpi", "plate_with_hole")
    shutil.copy(os.path.join(ROOT, "cases", "plate_with_hole", "plate_with_hole.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "plate_with_hole", "plate_with_hole.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    case["discretization"]["dx"] = 2.0e-3
    case["node_sets"]["left"]["layer"] = 6.0e-3
    case["node_sets"]["right"]["layer"] = 6.0e-3
    case["boundary_conditions"][0]["velocity"]["x"][1][1] = -1.0
    case["boundary_conditions"][1]["velocity"]["x"][1][1] = 1.0
    case["time"]["end"] = 3.0e-4
    case["output"]["every_time"] = 5.0e-5
    yaml_path = case_dir / "plate_with_hole.yaml"
    yaml_path.write_text(yaml.safe_dump(case))
    out = work / "prepared"
    prepare_stages(yaml_path, case_dir / "plate_with_hole.geo", out)
    return work, out


def copy_case(prepared, name, change=None):
    work, out = prepared
    target = work / name
    target.mkdir()
    shutil.copy(out / "nodes.vtu", target / "nodes.vtu")
    case = json.loads((out / "case.json").read_text())
    if change:
        change(case)
    (target / "case.json").write_text(json.dumps(case))
    return target


def solve(folder, ranks, threads=1, frames="gathered"):
    """frames: pdsolve --parallel-frames on several ranks. These tests compare frames byte for byte
    with the serial run's, so gathered on rank 0 unless a test asks for the pieces (None: the case's
    choice, pieces by default)."""
    command = [SOLVER, str(folder / "case.json"), "--quiet", "--threads", str(threads)]
    if ranks:
        command = [MPIEXEC, "--oversubscribe", "-np", str(ranks)] + command
        if frames:
            command += ["--parallel-frames", frames]
    return subprocess.run(command, capture_output=True, text=True, timeout=900, env=MPI_ENV)


def history_without_wall_time(folder):
    lines = (folder / "history.csv").read_text().splitlines()
    wall = lines[0].split(",").index("wall_time")
    return [",".join(v for k, v in enumerate(line.split(",")) if k != wall) for line in lines]


@pytest.fixture(scope="module")
def runs(prepared):
    folders = {}
    for name, ranks, threads in (("serial", None, 1), ("np1", 1, 1), ("np2", 2, 1), ("np3", 3, 1), ("np2t2", 2, 2)):
        folder = copy_case(prepared, name)
        result = solve(folder, ranks, threads)
        assert result.returncode == 0, f"{name}: {result.stdout}\n{result.stderr}"
        folders[name] = folder
    return folders


@pytest.mark.parametrize("name", ["np1", "np2", "np3", "np2t2"])
def test_frames_and_history_equal_the_serial_run_byte_for_byte(runs, name):
    serial, run = runs["serial"], runs[name]
    history = history_without_wall_time(serial)
    assert history_without_wall_time(run) == history
    # The run cracked the plate: bonds broke (across ranks too, on 2 and 3 of them).
    broken = history[0].split(",").index("broken_bonds")
    assert int(history[-1].split(",")[broken]) > 100
    assert (run / "frames.pvd").read_bytes() == (serial / "frames.pvd").read_bytes()
    frames = sorted(os.listdir(serial / "frames"))
    assert len(frames) == 7  # t = 0 and every 5e-5 s to 3e-4 s
    assert sorted(os.listdir(run / "frames")) == frames
    for frame in frames:
        assert (run / "frames" / frame).read_bytes() == (serial / "frames" / frame).read_bytes(), frame
    # Only rank 0 wrote: the same files as the serial run, no more.
    assert sorted(os.listdir(run)) == sorted(os.listdir(serial))


def with_loads(case):
    """Body forces (the whole plate in y, constant; the left grip in x, ramped) and two indenters: a disk
    pressing the top edge (y = 0.049 m) and a plane pushing the left edge (x = 0.001 m), both inside from t = 0."""
    case["boundary_conditions"] += [
        {"set": "plate", "kind": "body_force", "component": 1, "times": [0.0], "values": [-4.0e7]},
        {"set": "left", "kind": "body_force", "component": 0, "times": [0.0, 3.0e-4], "values": [0.0, 2.0e8]},
    ]
    case["indenters"] = [
        {"name": "punch", "shape": "cylinder", "radius": 5.0e-3, "centre": [0.05, 0.0538, 0.0],
         "velocity": [0.0, -5.0, 0.0], "axis": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, 0.0], "stiffness": 1.0e14},
        {"name": "wall", "shape": "plane", "radius": 0.0, "centre": [0.0013, 0.0, 0.0],
         "velocity": [1.0, 0.0, 0.0], "axis": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0], "stiffness": 1.0e14},
    ]
    # Probes (output.probes: exact sums, so any order) and a reaction (rank 0 adds the pieces' terms in
    # the serial order: core/reactions.hpp), neither gathering the whole state.
    case["output"]["probes"] = ["right", "plate"]
    case["output"]["reactions"] = ["right"]


def as_lps(case):
    """The plate of the linear peridynamic solid (two sweeps: the ghosts' P between them)."""
    for block in case["blocks"]:
        block["model"] = "lps"
        block["poisson_ratio"] = 0.3


def lps_corrected(case):
    """The LPS plate with the energy surface correction: its factors and LPS's m_i summed over each
    rank's own rows, the ghosts' from their owners (no rank holds the whole bond list)."""
    as_lps(case)
    case["surface_correction"] = "energy"


def adaptive(case):
    """The adaptive integrator (thesis §2.2), its default dt_max from the exact limit of the whole plate."""
    case["time"]["integrator"] = "adaptive"


def exact_dt(case):
    """Verlet at 0.9 × the exact limit 2/ω_max (Lanczos), which the ranks compute on their pieces
    (core/stability.hpp): the same bits as the serial run's."""
    case["time"]["dt"] = "exact"
    case["time"]["safety_factor"] = 0.9


def steps_of_the_plate(prepared):
    """Eq. 2.5's step and the exact limit 2/ω_max of the prepared plate, as pdsolve computes them."""
    _, out = prepared
    result = subprocess.run([SOLVER, "--stable-dt", str(out / "case.json"), "--exact"], capture_output=True,
                            text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    steps = json.loads(result.stdout)
    assert steps["stable"] < steps["exact"], steps
    return steps["stable"], steps["exact"]


def fixed_dt(prepared):
    """A fixed time.dt (what a LAMMPS deck gives) halfway between eq. 2.5 and the exact limit: set-up
    judges it against the exact limit (run.log's warning), on the pieces."""
    stable, exact = steps_of_the_plate(prepared)

    def change(case):
        case["time"]["dt"] = 0.5 * (stable + exact)
    return change


@pytest.fixture(scope="module", params=["loads", "lps", "lps_corrected", "adaptive", "exact", "fixed"])
def variant_runs(request, prepared):
    change = {"loads": with_loads, "lps": as_lps, "lps_corrected": lps_corrected, "adaptive": adaptive,
              "exact": exact_dt, "fixed": fixed_dt(prepared) if request.param == "fixed" else None}[request.param]
    folders = {}
    for name, ranks, threads in (("serial", None, 1), ("np2", 2, 1), ("np3", 3, 1), ("np2t2", 2, 2)):
        folder = copy_case(prepared, f"{request.param}_{name}", change)
        result = solve(folder, ranks, threads)
        assert result.returncode == 0, f"{request.param} {name}: {result.stdout}\n{result.stderr}"
        folders[name] = folder
    return request.param, folders


def test_loads_lps_and_adaptive_equal_the_serial_run_byte_for_byte(variant_runs):
    kind, runs = variant_runs
    serial = runs["serial"]
    history = history_without_wall_time(serial)
    header = history[0].split(",")
    last = history[-1].split(",")
    if kind == "loads":
        # The punch pressed and the wall pushed: their reactions are in the history, non-zero.
        assert "indenter_punch_fy" in header and "indenter_wall_fx" in header
        assert float(last[header.index("indenter_punch_fy")]) > 0.0
        assert float(last[header.index("indenter_wall_fx")]) < 0.0
        assert float(last[header.index("indenter_energy")]) > 0.0  # its own column since issue 16
        assert float(last[header.index("contact_energy")]) == 0.0   # no contact pairs in this scene
        assert float(last[header.index("reaction_right_fx")]) != 0.0
        # The right grip moves with its velocity table: its probe says so at the last row.
        case = json.loads((serial / "case.json").read_text())
        grip = next(bc for bc in case["boundary_conditions"]
                    if bc["set"] == "right" and bc["kind"] == "velocity" and bc["component"] == 0)
        t = float(last[header.index("time")])
        assert float(last[header.index("probe_right_vx")]) == pytest.approx(
            float(np.interp(t, grip["times"], grip["values"])), rel=1e-12)
        assert [name for name in header if name.startswith("probe_plate_")] == [
            f"probe_plate_{q}" for q in ("ux", "uy", "uz", "vx", "vy", "vz")]
    else:
        assert int(last[header.index("broken_bonds")]) > 100  # the plate cracked
    frames = sorted(os.listdir(serial / "frames"))
    for name in ("np2", "np3", "np2t2"):
        run = runs[name]
        assert history_without_wall_time(run) == history, f"{kind} {name}"
        assert (run / "frames.pvd").read_bytes() == (serial / "frames.pvd").read_bytes()
        assert sorted(os.listdir(run / "frames")) == frames
        for frame in frames:
            assert (run / "frames" / frame).read_bytes() == (serial / "frames" / frame).read_bytes(), (kind, name, frame)


def test_run_log_says_how_the_run_was_decomposed(runs):
    assert "decomposed" not in (runs["np1"] / "run.log").read_text()  # one rank: the serial path
    for name, ranks in (("np2", 2), ("np3", 3)):
        log = (runs[name] / "run.log").read_text()
        assert f"decomposed over {ranks} MPI ranks" in log, log
        assert "ghosts in all" in log


def bonds_held(log):
    """run.log's directed bonds in all (2 × its "bonds" count) and the directed bonds each rank holds."""
    total = 2 * int(re.search(r"^nodes \d+, bonds (\d+) ", log, re.M).group(1))
    line = re.search(r"^directed bonds held per rank \(of (\d+)\):(.*)$", log, re.M)
    assert line, log
    assert int(line.group(1)) == total
    held = [int(n) for n in re.findall(r"rank \d+ (\d+)", line.group(2))]
    return total, held, line.group(0)


def test_each_rank_holds_the_rows_of_its_own_nodes_only(runs):
    """A pmb plate at dt: stable needs no whole bond list: each rank builds only the rows of the nodes
    it owns (issue 15), so the ranks' bonds add up to the model's, each once, and no rank holds more
    than its share (before, every rank also held the whole list: held > total on each)."""
    for name, ranks in (("np2", 2), ("np3", 3), ("np2t2", 2)):
        total, held, line = bonds_held((runs[name] / "run.log").read_text())
        assert len(held) == ranks, line
        assert sum(held) == total, line
        assert all(0 < h < 0.6 * total for h in held), line
        assert "each rank built only the rows of its own nodes" in line


def node_data_held(log):
    """run.log's bytes of per-node data each rank holds after set-up: (whole cloud's, piece's) per rank."""
    line = re.search(r"^node data held per rank after set-up \(bytes: the whole cloud's arrays \+ the piece's\):(.*)$",
                     log, re.M)
    assert line, log
    return [(int(w), int(p)) for w, p in re.findall(r"rank \d+ (\d+) \+ (\d+)", line.group(1))]


def test_only_rank_0_keeps_the_whole_clouds_node_data(runs):
    """Ranks other than 0 free the whole cloud's per-node arrays once their piece is cut (issue 15:
    positions, volumes, blocks, sets, densities, conditions, the rows' offsets); rank 0 keeps them
    for the gathered output. What a rank other than 0 then holds is its piece's, which falls with R
    (before, every rank held the whole cloud's arrays: each held at least rank 0's bytes)."""
    nodes = int(re.search(r"^nodes (\d+),", (runs["np2"] / "run.log").read_text(), re.M).group(1))
    held = {name: node_data_held((runs[name] / "run.log").read_text()) for name in ("np2", "np3", "np2t2")}
    whole = held["np2"][0][0]
    # x, y, z, volume, density (8 bytes each), block, block index (4), no-fail (1), offsets (8 per node + 8).
    assert whole >= 57 * nodes, held
    for name, ranks in (("np2", 2), ("np3", 3), ("np2t2", 2)):
        assert len(held[name]) == ranks, held
        assert held[name][0][0] == whole, held  # rank 0 writes the output from the whole cloud
        assert all(w == 0 for w, _ in held[name][1:]), held
        # A piece is its owned nodes and their ghosts (3 layers each side on this coarse plate).
        assert all(0 < piece < 0.6 * whole for _, piece in held[name]), held
    assert max(p for _, p in held["np3"]) < max(p for _, p in held["np2"]), held


def test_a_feature_that_reads_whole_rows_keeps_the_whole_list_and_says_so(variant_runs):
    """No feature keeps the whole bond list on every rank any more (issue 37, item 3): the exact limit —
    dt: exact, a fixed dt above eq. 2.5, the adaptive step's default dt_max, the indenters' depth
    bound — runs its Lanczos on the pieces, and LPS's per-node constants and the surface correction's
    factors are summed over each rank's own rows, the ghosts' from their owners: each rank holds
    only its rows, and run.log says so."""
    kind, folders = variant_runs
    for name, ranks in (("np2", 2), ("np3", 3), ("np2t2", 2)):
        total, held, line = bonds_held((folders[name] / "run.log").read_text())
        assert len(held) == ranks, line
        assert "every rank holds the whole bond list too" not in line, line
        assert "each rank built only the rows of its own nodes" in line, line
        assert sum(held) == total and all(0 < h < 0.6 * total for h in held), line


def step_lines(log):
    """run.log's lines on the step and the exact limit: the dt line, the set-up's warning, the
    adaptive step's dt_max and the indenters' depth bounds."""
    lines = [line for line in log.splitlines()
             if line.startswith(("dt ", "warning: the fixed dt", "adaptive", "indenter '"))]
    # The adaptive line's note on where its default came from names the Lanczos wall time serially.
    return [line.split(" (default:")[0] for line in lines]


def test_the_exact_limit_on_the_pieces_is_the_serial_one(variant_runs):
    """What run.log says of the step, computed on the pieces (the exact limit, the fixed dt's warning,
    the default dt_max, the indenters' depth), is the serial run's, digit for digit."""
    kind, folders = variant_runs
    serial = step_lines((folders["serial"] / "run.log").read_text())
    assert serial, kind
    if kind == "fixed":
        assert any("exceeds the stable time step of thesis eq. 2.5" in line and "but not the exact limit" in line
                   for line in serial), serial
    if kind == "exact":
        assert any("exact limit" in line for line in serial), serial
    if kind == "loads":
        assert sum(line.startswith("indenter '") for line in serial) == 2, serial
    for name in ("np2", "np3", "np2t2"):
        assert step_lines((folders[name] / "run.log").read_text()) == serial, (kind, name)


def test_what_is_not_decomposed_is_refused_before_any_output(prepared):
    """quasi_static's amg preconditioner is set up on one process's assembled tangent: refused on
    several ranks, once, by rank 0, before any output. (Contact inside a Newton solve, refused here
    before, is decomposed now: test_mpi_newton_contact.py.)"""
    def amg_on_ranks(case):
        case["time"]["integrator"] = "quasi_static"
        case["damping"] = 0.0  # quasi_static refuses damping (before the preconditioner)
        case["quasi_static"]["preconditioner"] = "amg"
    folder = copy_case(prepared, "refused", amg_on_ranks)
    result = solve(folder, 2)
    assert result.returncode != 0
    assert ("quasi_static.preconditioner: amg is set up on one process and is not decomposed over MPI ranks "
            "(here 2); use preconditioner: block_jacobi (or auto), or run on one rank") in result.stderr, result.stderr
    assert result.stderr.count("pdsolve: error") == 1  # said once, by rank 0
    assert not (folder / "history.csv").exists() and not (folder / "frames").exists()


def test_a_usage_error_is_said_once_under_mpiexec(prepared):
    """The options are read before MPI starts; every rank finds the mistake, rank 0 alone says it
    (it printed the 40-line usage once per rank)."""
    folder = copy_case(prepared, "usage")
    result = subprocess.run([MPIEXEC, "--oversubscribe", "-np", "2", SOLVER, str(folder / "case.json"), "--bogus"],
                            capture_output=True, text=True, timeout=120, env=MPI_ENV)
    assert result.returncode != 0
    assert result.stderr.count("unknown option '--bogus'") == 1, result.stderr
    assert result.stderr.count("usage: pdsolve") == 1, result.stderr
