"""End to end: checkpoints and restarts of a run on several MPI ranks (issue 15).

Rank 0 gathers the state in global node order and writes the serial run's checkpoint.bin; a restart
reads it on any rank count. On the coarse plate of test_mpi_ranks.py (1234 nodes, cracking):
- a checkpoint written on 2 ranks restarts on 3 ranks and on 1 (no mpirun), and either continues
  the run byte for byte as the uninterrupted serial run (frames, frames.pvd, history.csv but for
  its wall_time column);
- SIGTERM to mpirun (what a batch system sends at the end of a job) makes the ranks stop after the
  same step and write a checkpoint, from which the run continues byte for byte;
- a rank killed with SIGKILL makes mpirun end the others within seconds with a non-zero code, and
  the last periodic checkpoint continues the run byte for byte.
"""
import os
import re
import shutil
import signal
import subprocess
import time

import pytest

from e2e_support import SOLVER  # noqa: E402
# prepared: the coarse plate, meshed and preprocessed once per module; pytestmark: skip without MPI.
from test_mpi_ranks import (MPI_ENV, MPIEXEC, adaptive, as_lps, copy_case,  # noqa: F401, F811
                            history_without_wall_time, prepared, pytestmark, solve, with_loads)

# Within this many seconds of a rank's death mpirun must have ended the others (measured: 2.1 s
# with the machine's load average at 21 on 2 cores).
DEATH_NOTICED_WITHIN_S = 30


# The interrupted runs: 10 ms (about 9 200 steps), a checkpoint every 0.1 ms. Long enough that a
# signal sent after the first checkpoint finds the run still going on a quiet machine too: at 2 ms
# the whole 2-rank run took 0.41 s and ended before mpirun had passed SIGTERM on.
LONG_END, LONG_EVERY = 5.0e-2, 1.0e-4   # 5e-2: on a quiet machine a 1e-2 run (0.97 s on 2 ranks) ended before the SIGTERM sent at its first checkpoint arrived


def with_checkpoints(end, every):
    def change(case):
        case["time"]["end"] = end
        case["output"]["restart_every_time"] = every
    return change


def restart(folder, ranks, timeout=900, frames="gathered"):
    """frames: as test_mpi_ranks.solve's."""
    command = [SOLVER, str(folder / "case.json"), "--quiet", "--threads", "1", "--restart", str(folder / "checkpoint.bin")]
    if ranks:
        command = [MPIEXEC, "--oversubscribe", "-np", str(ranks)] + command
        if frames:
            command += ["--parallel-frames", frames]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=MPI_ENV)


def assert_same_run(reference, run):
    assert history_without_wall_time(run) == history_without_wall_time(reference)
    assert (run / "frames.pvd").read_bytes() == (reference / "frames.pvd").read_bytes()
    frames = sorted(os.listdir(reference / "frames"))
    assert sorted(os.listdir(run / "frames")) == frames
    for frame in frames:
        assert (run / "frames" / frame).read_bytes() == (reference / "frames" / frame).read_bytes(), frame


def restarted_at_step(folder):
    for line in (folder / "run.log").read_text().splitlines():
        if line.startswith("restart from "):
            return int(line.split("step ")[1].split(",")[0])
    raise AssertionError(f"no restart line in {folder / 'run.log'}")


def start_two_ranks(folder):
    command = [MPIEXEC, "--oversubscribe", "-np", "2", SOLVER, str(folder / "case.json"), "--quiet", "--threads", "1",
               "--parallel-frames", "gathered"]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=MPI_ENV)


def wait_for_checkpoint(folder, process, timeout=600):
    start = time.monotonic()
    while not (folder / "checkpoint.bin").exists():
        assert process.poll() is None, f"the run ended before its first checkpoint: {process.communicate()}"
        assert time.monotonic() - start < timeout, "no checkpoint written"
        time.sleep(0.05)


def rank_pid(mpirun_pid, rank):
    """The pid of MPI rank `rank` among mpirun's children (OpenMPI gives each its rank in
    OMPI_COMM_WORLD_RANK)."""
    for pid in subprocess.run(["pgrep", "-P", str(mpirun_pid)], capture_output=True, text=True).stdout.split():
        with open(f"/proc/{pid}/environ", "rb") as stream:
            if f"OMPI_COMM_WORLD_RANK={rank}".encode() in stream.read().split(b"\0"):
                return int(pid)
    raise AssertionError(f"no rank {rank} among the children of mpirun {mpirun_pid}")


def test_a_checkpoint_written_on_2_ranks_continues_on_3_and_on_1_bitwise(prepared):
    change = with_checkpoints(3.0e-4, 1.2e-4)
    reference = copy_case(prepared, "ckpt_reference", change)
    assert solve(reference, None).returncode == 0
    written = copy_case(prepared, "ckpt_np2", change)
    result = solve(written, 2)
    assert result.returncode == 0, result.stderr
    assert (written / "checkpoint.bin").exists()
    assert_same_run(reference, written)  # the checkpoints cost nothing in the results
    # run.log's traffic lines, one per rank: the pieces cover the nodes once, each sends one halo
    # message a step of 24 bytes per ghost it fills on the other rank (2 ranks: the same count).
    traffic = re.findall(r"rank (\d): (\d+) owned nodes, (\d+) ghosts .*?; per step: .*?, ([0-9.]+) messages and ([0-9.e+]+) "
                         r"bytes sent, .* ms in communication .*; peak memory ([0-9.]+) MB", (written / "run.log").read_text())
    assert [t[0] for t in traffic] == ["0", "1"]
    nodes = int(re.search(r"nodes (\d+),", (written / "run.log").read_text()).group(1))
    assert sum(int(t[1]) for t in traffic) == nodes > 1000
    for rank, _, _, messages, sent, peak in traffic:
        assert float(messages) == 1.0
        other_ghosts = int(traffic[1 - int(rank)][2])  # what this rank sends is what the other rank receives
        assert 24 * other_ghosts <= float(sent) <= 24 * other_ghosts * 1.01  # (+ the start's evaluation, over ~270 steps)
        assert float(peak) > 0.0
    for name, ranks in (("ckpt_np2_to_np3", 3), ("ckpt_np2_to_serial", None)):
        folder = prepared[0] / name
        shutil.copytree(written, folder)
        result = restart(folder, ranks)
        assert result.returncode == 0, f"{name}: {result.stderr}"
        # From the last periodic checkpoint (t ≥ 2.4e-4 s), not from the start.
        assert restarted_at_step(folder) > 200, (folder / "run.log").read_text()
        assert_same_run(reference, folder)


def test_wall_time_checkpoints_on_2_ranks_change_no_bit_and_continue_bitwise(prepared):
    """output.restart_every_wall (issue 36, item 8) on 2 ranks: rank 0's clock decides, and the
    reduction that carries the signal tells rank 1, so both take part in the same checkpoints (a
    checkpoint is collective: a rank left out would hang the run). At 1 ns every step is due but
    for the 3 % bound (a checkpoint here takes some 10 ms: one every ~0.3 s of a ~2 s run). The
    frames and history are the serial run's; the last checkpoint continues the run bitwise."""
    def wall(case):
        case["time"]["end"] = 2.0e-3
        case["output"]["restart_every_wall"] = 1.0e-9
    reference = copy_case(prepared, "wall_reference", with_checkpoints(2.0e-3, 1.0))
    assert solve(reference, None).returncode == 0
    written = copy_case(prepared, "wall_np2", wall)
    result = solve(written, 2)
    assert result.returncode == 0, result.stderr
    assert_same_run(reference, written)
    log = (written / "run.log").read_text()
    assert len(re.findall(r"^checkpoint: .*checkpoint\.bin at step \d+, .*restart_every_wall 1e-09 s", log, re.M)) >= 2, log
    folder = prepared[0] / "wall_np2_to_np2"
    shutil.copytree(written, folder)
    result = restart(folder, 2)
    assert result.returncode == 0, result.stderr
    assert restarted_at_step(folder) > 0
    assert_same_run(reference, folder)


@pytest.fixture(scope="module")
def long_reference(prepared):
    """A run long enough to be interrupted (LONG_END), serial and uninterrupted."""
    reference = copy_case(prepared, "long_reference", with_checkpoints(LONG_END, LONG_EVERY))
    result = solve(reference, None)
    assert result.returncode == 0, result.stderr
    return reference


def test_sigterm_to_mpirun_writes_a_checkpoint_that_continues_bitwise(prepared, long_reference):
    folder = copy_case(prepared, "sigterm", with_checkpoints(LONG_END, LONG_EVERY))
    process = start_two_ranks(folder)
    wait_for_checkpoint(folder, process)
    process.send_signal(signal.SIGTERM)  # mpirun passes it on to every rank
    _, stderr = process.communicate(timeout=120)
    assert process.returncode != 0
    log = (folder / "run.log").read_text()
    assert "interrupted by SIGTERM" in log and "checkpoint written" in log, log + stderr
    assert "continue with: mpiexec -np R pdsolve" in log  # any rank count R continues it
    result = restart(folder, 3)
    assert result.returncode == 0, result.stderr
    assert restarted_at_step(folder) > 0
    assert_same_run(long_reference, folder)


def test_a_killed_rank_ends_the_run_within_seconds_and_the_last_checkpoint_continues_it(prepared, long_reference):
    folder = copy_case(prepared, "killed", with_checkpoints(LONG_END, LONG_EVERY))
    process = start_two_ranks(folder)
    wait_for_checkpoint(folder, process)
    os.kill(rank_pid(process.pid, 1), signal.SIGKILL)
    killed = time.monotonic()
    try:
        process.communicate(timeout=DEATH_NOTICED_WITHIN_S)
    except subprocess.TimeoutExpired:
        process.kill()
        process.communicate()
        pytest.fail(f"rank 0 still ran {DEATH_NOTICED_WITHIN_S} s after rank 1 was killed")
    assert process.returncode != 0
    assert time.monotonic() - killed < DEATH_NOTICED_WITHIN_S
    assert "interrupted" not in (folder / "run.log").read_text()  # killed, not stopped: no checkpoint of its own
    result = restart(folder, 2)
    assert result.returncode == 0, result.stderr
    assert restarted_at_step(folder) > 0  # from a periodic checkpoint
    assert_same_run(long_reference, folder)


def test_a_checkpoint_rank_0_cannot_write_ends_every_rank_with_the_error(prepared):
    """Rank 0 alone writes files, so only it meets an output error; the other ranks must not wait
    for it for ever (before: rank 1 waited in the halo exchange and rank 0 in MPI_Finalize)."""
    folder = copy_case(prepared, "unwritable", with_checkpoints(2.0e-3, 1.0e-4))
    (folder / "checkpoint.bin.part").mkdir()  # the checkpoint's temporary name: open() fails
    started = time.monotonic()
    result = subprocess.run([MPIEXEC, "--oversubscribe", "-np", "2", SOLVER, str(folder / "case.json"), "--quiet",
                             "--threads", "1", "--parallel-frames", "gathered"], capture_output=True, text=True, timeout=300,
                            env=MPI_ENV)
    assert result.returncode == 3, result.stderr
    assert time.monotonic() - started < 300
    message = "checkpoint.bin.part: cannot open for writing: Is a directory"
    assert message in result.stderr and message in (folder / "run.log").read_text()
    assert not (folder / "checkpoint.bin").exists()


def test_a_restart_rank_0_refuses_is_refused_by_every_rank_at_once(prepared):
    """Rank 0 alone opens the output, so only it sees that a frame the checkpoint counts is
    missing; every rank must stop with its message (before: rank 0 in MPI_Finalize, rank 1 in the
    first halo exchange, for ever)."""
    folder = copy_case(prepared, "frame_missing", with_checkpoints(3.0e-4, 1.2e-4))
    assert solve(folder, 2).returncode == 0
    (folder / "frames" / "frame_000001.vtu").unlink()
    history = (folder / "history.csv").read_bytes()
    result = restart(folder, 2, timeout=180)  # before the fix it never returned
    assert result.returncode == 1, result.stderr
    assert result.stderr.count("frame_000001.vtu: missing, but the checkpoint counts") == 1  # said once, by rank 0
    assert "to start the run over instead, delete" in result.stderr
    assert (folder / "history.csv").read_bytes() == history  # refused before any file changed


@pytest.mark.parametrize("kind, change", [("loads", with_loads), ("lps", as_lps), ("adaptive", adaptive)])
def test_checkpoints_of_the_other_decomposed_terms_continue_bitwise(prepared, kind, change):
    """Body forces and indenters (their work and the indenters' forces are whole-body totals that
    a restart hands to every rank's piece), LPS (the ghosts' P) and the adaptive integrator (its
    saved step proposal): written on 2 ranks, continued on 3, equal to the serial uninterrupted run."""
    def with_both(case):
        change(case)
        with_checkpoints(3.0e-4, 1.2e-4)(case)
    reference = copy_case(prepared, f"{kind}_ckpt_reference", with_both)
    result = solve(reference, None)
    assert result.returncode == 0, result.stderr
    written = copy_case(prepared, f"{kind}_ckpt_np2", with_both)
    result = solve(written, 2)
    assert result.returncode == 0, result.stderr
    assert_same_run(reference, written)
    folder = prepared[0] / f"{kind}_ckpt_np2_to_np3"
    shutil.copytree(written, folder)
    result = restart(folder, 3)
    assert result.returncode == 0, f"{kind}: {result.stderr}"
    assert restarted_at_step(folder) > 0
    assert_same_run(reference, folder)


def pieces_of_checkpoint(folder):
    return sorted(p.name for p in (folder / "checkpoint.pieces").iterdir())


@pytest.fixture(scope="module")
def written_on_2(prepared):
    """A run on 2 ranks with checkpoints (the pieces format, issue 37) and its serial reference."""
    change = with_checkpoints(3.0e-4, 1.2e-4)
    reference = copy_case(prepared, "pieces_reference", change)
    assert solve(reference, None).returncode == 0
    written = copy_case(prepared, "pieces_np2", change)
    result = solve(written, 2)
    assert result.returncode == 0, result.stderr
    return reference, written


def test_each_rank_writes_its_piece_and_the_index_names_only_the_last_checkpoints(written_on_2):
    reference, written = written_on_2
    pieces = pieces_of_checkpoint(written)
    step = re.fullmatch(r"s(\d+)\.p0\.bin", pieces[0]).group(1)
    assert pieces == [f"s{step}.p0.bin", f"s{step}.p1.bin"]  # the earlier checkpoints' pieces went
    assert int(step) == restarted_at_step_of_index(written)
    # No piece holds the whole model: each is well under the serial run's one piece.
    serial = pieces_of_checkpoint(reference)
    assert len(serial) == 1
    whole = (reference / "checkpoint.pieces" / serial[0]).stat().st_size
    for name in pieces:
        assert (written / "checkpoint.pieces" / name).stat().st_size < 0.75 * whole


def restarted_at_step_of_index(folder):
    """The step of the checkpoint, as its index names its pieces (s<step>.pR.bin)."""
    data = (folder / "checkpoint.bin").read_bytes()
    return int(re.search(rb"checkpoint\.pieces/s(\d+)\.p0\.bin", data).group(1))


@pytest.mark.parametrize("ranks", [1, 2, 3])
def test_a_checkpoint_in_pieces_restarts_on_any_rank_count_bitwise(prepared, written_on_2, ranks):
    reference, written = written_on_2
    folder = prepared[0] / f"pieces_np2_to_{ranks}"
    shutil.copytree(written, folder)
    result = restart(folder, ranks if ranks > 1 else None)
    assert result.returncode == 0, result.stderr
    assert restarted_at_step(folder) == restarted_at_step_of_index(written) > 200
    assert_same_run(reference, folder)


def test_a_crash_while_writing_a_checkpoint_leaves_the_previous_one_usable(prepared, written_on_2):
    """A run killed after some ranks wrote their pieces of a later checkpoint but before rank 0
    renamed the new index into place: the pieces of that step and a half-written index lie beside
    the previous checkpoint, which still continues the run bitwise."""
    reference, written = written_on_2
    folder = prepared[0] / "pieces_crash"
    shutil.copytree(written, folder)
    step = restarted_at_step_of_index(folder)
    stray = folder / "checkpoint.pieces" / f"s{step + 7}.p0.bin"
    stray.write_bytes(b"half a piece")
    (folder / "checkpoint.bin.part").write_bytes(b"half an index")
    result = restart(folder, 3)
    assert result.returncode == 0, result.stderr
    assert_same_run(reference, folder)


@pytest.mark.parametrize("damage", ["missing", "flipped", "foreign"])
def test_a_bad_piece_is_named_before_any_output_changes(prepared, written_on_2, damage):
    reference, written = written_on_2
    folder = prepared[0] / f"pieces_{damage}"
    shutil.copytree(written, folder)
    step = restarted_at_step_of_index(folder)
    piece = folder / "checkpoint.pieces" / f"s{step}.p1.bin"
    if damage == "missing":
        piece.unlink()
        expected = f"{piece}: missing, but {folder / 'checkpoint.bin'} names it as piece 1 of 2"
    elif damage == "flipped":
        data = bytearray(piece.read_bytes())
        data[len(data) // 2] ^= 0x04
        piece.write_bytes(bytes(data))
        expected = f"{piece}: checkpoint piece checksum mismatch"
    else:  # rank 0's piece in place of rank 1's: another size
        shutil.copy(folder / "checkpoint.pieces" / f"s{step}.p0.bin", piece)
        expected = f"{piece}: "
    before = {p.relative_to(folder): p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    result = restart(folder, 3, timeout=180)
    assert result.returncode == 1, result.stderr
    assert expected in result.stderr, result.stderr
    assert "to start the run over instead, delete" in result.stderr
    after = {p.relative_to(folder): p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    assert after == before  # no output written: frames, history.csv, run.log as they were
