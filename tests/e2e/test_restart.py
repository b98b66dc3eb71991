"""End to end: pdsolve stopped by SIGTERM mid-run writes a checkpoint and only whole files, and
`pdsolve --restart` continues to bitwise the result of an uninterrupted run.

A coarse, short copy of cases/membrane goes through mesh and preprocess as the Makefile calls them;
pdsolve runs once uninterrupted, once with SIGTERM after a few frames, then restarts.
"""
import csv
import json
import os
import shutil
import signal
import subprocess
import time

import meshio
import numpy as np
import pytest
import yaml

from e2e_support import ROOT, SOLVER, new_case_folder, prepare_stages  # noqa: E402
FRAMES = 50  # frames of the whole run: enough that SIGTERM lands mid-run


@pytest.fixture(scope="module")
def prepared(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "restart", "membrane")
    shutil.copy(os.path.join(ROOT, "cases", "membrane", "membrane.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    case["discretization"]["dx"] = 0.002
    case["node_sets"]["clamped"]["layer"] = 0.006
    case["time"]["end"] = 1.0e-2
    case["output"] = {"every_time": 1.0e-2 / FRAMES, "restart_every_steps": 500}
    case["figures"]["times"] = [0.0]
    yaml_path = case_dir / "membrane.yaml"
    yaml_path.write_text(yaml.safe_dump(case))
    out = work / "prepared"
    prepare_stages(yaml_path, case_dir / "membrane.geo", out)
    return work, out


def copy_case(prepared, name):
    work, out = prepared
    target = work / name
    target.mkdir()
    for f in ("case.json", "nodes.vtu"):
        shutil.copy(out / f, target / f)
    return target


@pytest.fixture(scope="module")
def runs(prepared):
    whole = copy_case(prepared, "whole")
    result = subprocess.run([SOLVER, str(whole / "case.json"), "--quiet", "--threads", "1"],
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr

    cut = copy_case(prepared, "cut")
    proc = subprocess.Popen([SOLVER, str(cut / "case.json"), "--quiet", "--threads", "1"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None:
        if (cut / "frames" / "frame_000004.vtu").exists():
            break
        time.sleep(0.01)
    assert proc.poll() is None, "the run ended before it could be interrupted"
    proc.send_signal(signal.SIGTERM)
    stdout, stderr = proc.communicate(timeout=300)
    interrupted = {"code": proc.returncode, "stderr": stderr,
                   "frames": sorted(os.listdir(cut / "frames")),
                   "files": sorted(os.listdir(cut)),
                   "history": (cut / "history.csv").read_text()}

    restart = subprocess.run([SOLVER, str(cut / "case.json"), "--quiet", "--threads", "1",
                              "--restart", str(cut / "checkpoint.bin")],
                             capture_output=True, text=True, timeout=600)
    assert restart.returncode == 0, restart.stderr
    return whole, cut, interrupted


@pytest.fixture(scope="module")
def killed(prepared):
    """SIGKILL (no chance to checkpoint) after some frames; restart from the last periodic checkpoint."""
    cut = copy_case(prepared, "killed")
    proc = subprocess.Popen([SOLVER, str(cut / "case.json"), "--quiet", "--threads", "1"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None:
        if (cut / "frames" / "frame_000010.vtu").exists():
            break
        time.sleep(0.01)
    assert proc.poll() is None, "the run ended before it could be killed"
    proc.kill()
    proc.wait(timeout=60)
    history = (cut / "history.csv").read_text()
    files = sorted(os.listdir(cut))
    restart = subprocess.run([SOLVER, str(cut / "case.json"), "--quiet", "--threads", "1",
                              "--restart", str(cut / "checkpoint.bin")],
                             capture_output=True, text=True, timeout=600)
    assert restart.returncode == 0, restart.stderr
    return cut, history, files


def test_sigkill_then_restart_from_the_periodic_checkpoint(runs, killed):
    whole = runs[0]
    cut, history, files = killed
    assert "checkpoint.bin" in files
    width = len(history.splitlines()[0].split(","))
    assert all(len(line.split(",")) == width for line in history.splitlines()[:-1])
    for name in sorted(os.listdir(whole / "frames"))[-1:]:
        a, b = meshio.read(whole / "frames" / name), meshio.read(cut / "frames" / name)
        for key in ("displacement", "velocity", "damage"):
            assert np.array_equal(a.point_data[key], b.point_data[key]), f"{name}: {key} differs"
    rows = read_history(cut / "history.csv")
    assert [int(r["step"]) for r in rows] == list(range(len(rows)))
    assert len(rows) == len(read_history(whole / "history.csv"))


@pytest.fixture(scope="module")
def killed_with_wall_checkpoints_only(prepared):
    """Checkpoints by wall time alone (output.restart_every_wall, issue 36 item 8: on by default, here
    every 0.05 s), then SIGKILL after some frames: the run has a checkpoint all the same, and the
    restart from it continues the run bitwise."""
    cut = copy_case(prepared, "killed_wall")
    case = json.loads((cut / "case.json").read_text())
    case["output"]["restart_every_steps"] = None
    case["output"]["restart_every_wall"] = 0.05
    (cut / "case.json").write_text(json.dumps(case))
    proc = subprocess.Popen([SOLVER, str(cut / "case.json"), "--quiet", "--threads", "1"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None:
        if (cut / "frames" / "frame_000010.vtu").exists() and (cut / "checkpoint.bin").exists():
            break
        time.sleep(0.01)
    assert proc.poll() is None, f"the run ended before it could be killed: {proc.communicate()[1]}"
    proc.kill()
    proc.wait(timeout=60)
    proc.stderr.close()
    files = sorted(os.listdir(cut))
    restart = subprocess.run([SOLVER, str(cut / "case.json"), "--quiet", "--threads", "1",
                              "--restart", str(cut / "checkpoint.bin")],
                             capture_output=True, text=True, timeout=600)
    assert restart.returncode == 0, restart.stderr
    return cut, files


def test_sigkill_then_restart_from_a_wall_time_checkpoint(runs, killed_with_wall_checkpoints_only):
    whole = runs[0]
    cut, files = killed_with_wall_checkpoints_only
    assert "checkpoint.bin" in files
    assert "restart from" in (cut / "run.log").read_text()
    assert (whole / "frames.pvd").read_text() == (cut / "frames.pvd").read_text()
    for name in sorted(os.listdir(whole / "frames")):
        assert (whole / "frames" / name).read_bytes() == (cut / "frames" / name).read_bytes(), name
    a, b = read_history(whole / "history.csv"), read_history(cut / "history.csv")
    assert len(a) == len(b)
    for ra, rb in zip(a, b):
        ra.pop("wall_time"), rb.pop("wall_time")
        assert ra == rb


def test_the_default_case_json_asks_for_a_checkpoint_every_600_s(prepared):
    _, out = prepared
    assert json.loads((out / "case.json").read_text())["output"]["restart_every_wall"] == 600.0


def read_history(path):
    with open(path, newline="") as stream:
        return list(csv.DictReader(stream))


def test_sigterm_writes_a_checkpoint_and_exits_143(runs):
    whole, cut, interrupted = runs
    assert interrupted["code"] == 128 + signal.SIGTERM, interrupted["stderr"]
    assert "interrupted by SIGTERM" in interrupted["stderr"]
    assert "--restart" in interrupted["stderr"]
    assert "checkpoint.bin" in interrupted["files"]
    assert 5 <= len(interrupted["frames"]) < FRAMES + 1


def test_no_truncated_files_after_sigterm(runs):
    whole, cut, interrupted = runs
    assert not [f for f in interrupted["files"] + interrupted["frames"] if f.endswith(".part")]
    history = interrupted["history"]
    assert history.endswith("\n"), "history.csv ends in a partial line"
    width = len(history.splitlines()[0].split(","))
    assert all(len(line.split(",")) == width for line in history.splitlines())


def test_restart_reproduces_the_uninterrupted_run_exactly(runs):
    whole, cut, _ = runs
    names = sorted(os.listdir(whole / "frames"))
    assert names == sorted(os.listdir(cut / "frames"))
    assert len(names) == FRAMES + 1
    for name in (names[-1], names[len(names) // 2]):
        a, b = meshio.read(whole / "frames" / name), meshio.read(cut / "frames" / name)
        for key in ("displacement", "velocity", "damage"):
            assert np.array_equal(a.point_data[key], b.point_data[key]), f"{name}: {key} differs"
    assert (whole / "frames.pvd").read_text() == (cut / "frames.pvd").read_text()


def test_history_has_every_step_once_and_the_same_rows(runs):
    whole, cut, _ = runs
    a, b = read_history(whole / "history.csv"), read_history(cut / "history.csv")
    steps = [int(r["step"]) for r in b]
    assert steps == list(range(len(steps))), "history.csv has duplicated or missing steps"
    assert len(a) == len(b)
    for ra, rb in zip(a, b):
        ra.pop("wall_time"), rb.pop("wall_time")
        assert ra == rb


def test_run_log_tells_the_story(runs):
    _, cut, _ = runs
    log = (cut / "run.log").read_text()
    assert "interrupted: " in log and "restart from" in log and "done: " in log


def test_the_restarted_runs_rate_counts_only_its_own_steps(runs):
    # "done: N steps … in W s wall (R bond updates/s)": R·W is the bond updates of the run that
    # printed it, so the restart's R·W over the whole run's is its share of the steps, N − M over N
    # (M the step it restarted from), not N/N (fixed: the rate divided every step by the restart's
    # wall time alone: N/(N − M) times too high).
    import re
    line = re.compile(r"(done|interrupted): (\d+) steps to t = \S+ s in ([\d.]+) s wall \(([\d.e+-]+) bond updates/s\)")
    whole, cut, _ = runs
    (_, n_whole, w_whole, r_whole), = line.findall((whole / "run.log").read_text())
    (_, m, _, _), (_, n, w_restart, r_restart) = line.findall((cut / "run.log").read_text())
    assert int(n) == int(n_whole) and 0 < int(m) < int(n)
    share = float(r_restart) * float(w_restart) / (float(r_whole) * float(w_whole))
    assert share == pytest.approx((int(n) - int(m)) / int(n), rel=0.05)
