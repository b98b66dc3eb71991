"""End to end: frames in pieces (`output.parallel_frames: pieces`, issue 15) on 2 and 3 MPI ranks.

On the coarse cracking plate of test_mpi_ranks.py (1234 nodes, 7 frames), every rank writes its
piece of each frame (its nodes and their ghosts, marked by vtkGhostType) and rank 0 a .pvtu naming
them, which frames.pvd lists. Checked against the serial run's gathered frames: the owned points of
the pieces are every node once, with the serial frame's displacement, velocity, damage and block
bit for bit, and the pieces' broken-bond lines are the serial frame's; history.csv is the serial
run's. ParaView (pvpython, skipped without it) opens the series and sees every node once per frame.
postprocess reads a .pvtu as the gathered frame of the same run, bit for bit. A checkpoint of a run in pieces on
2 ranks continues on 3 with the series of the uninterrupted run.
"""
import os
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from e2e_support import PY, ROOT, SOLVER
from postprocess import read_frame
# prepared: the coarse plate, meshed and preprocessed once per module; pytestmark: skip without MPI.
from test_mpi_checkpoint import assert_same_run, restart, restarted_at_step, with_checkpoints
from test_mpi_ranks import copy_case, history_without_wall_time, prepared, pytestmark, solve  # noqa: F401, F811

PVPYTHON = shutil.which("pvpython")


def in_pieces(case):
    """No output.parallel_frames at all: pdsolve's default on several ranks is pieces."""
    case["output"].pop("parallel_frames", None)


def listed(folder):
    """(timestep, file) of frames.pvd, in order."""
    root = ET.parse(folder / "frames.pvd").getroot()
    return [(d.get("timestep"), d.get("file")) for d in root.iter("DataSet")]


def pieces_of(pvtu):
    root = ET.parse(pvtu).getroot()
    assert root.get("type") == "PUnstructuredGrid"
    return [pvtu.parent / p.get("Source") for p in root.iter("Piece")]


def assembled(pvtu):
    """The owned points of every piece, in global node order: (node ids, point data), and the set of
    broken bonds (global numbers)."""
    ids, data, bonds = [], {}, set()
    for piece in pieces_of(pvtu):
        frame = read_frame(str(piece))
        node = frame.point_data["node_id"].astype(np.int64).reshape(-1)
        owned = frame.point_data["vtkGhostType"].reshape(-1) == 0
        ids.append(node[owned])
        for name in ("displacement", "velocity", "damage", "block"):
            data.setdefault(name, []).append(frame.point_data[name][owned])
        bonds |= {tuple(sorted((int(node[i]), int(node[j])))) for i, j in frame.broken_bonds}
    order = np.argsort(np.concatenate(ids))
    return np.concatenate(ids)[order], {k: np.concatenate(v)[order] for k, v in data.items()}, bonds


@pytest.fixture(scope="module")
def runs(prepared):
    folders = {"serial": copy_case(prepared, "gathered_serial")}
    assert solve(folders["serial"], None).returncode == 0
    for ranks in (2, 3):
        folders[ranks] = copy_case(prepared, f"pieces_np{ranks}", in_pieces)
        result = solve(folders[ranks], ranks, frames=None)  # the default on several ranks: pieces
        assert result.returncode == 0, result.stderr
    return folders


@pytest.mark.parametrize("ranks", [2, 3])
def test_the_pieces_hold_every_node_once_with_the_serial_frames_values(runs, ranks):
    serial, run = runs["serial"], runs[ranks]
    assert history_without_wall_time(run) == history_without_wall_time(serial)
    gathered = listed(serial)
    assert len(gathered) == 7
    assert listed(run) == [(t, f.replace(".vtu", ".pvtu")) for t, f in gathered]
    for (_, file), (_, pfile) in zip(gathered, listed(run)):
        pieces = pieces_of(run / pfile)
        assert [p.name for p in pieces] == [f"{os.path.basename(file)[:-4]}_p{r}.vtu" for r in range(ranks)]
        whole = read_frame(str(serial / file))
        ids, data, bonds = assembled(run / pfile)
        assert ids.tolist() == list(range(len(whole.points)))  # every node once
        for name, values in data.items():
            assert np.array_equal(values, whole.point_data[name]), (file, name)
        assert bonds == {tuple(sorted(map(int, b))) for b in whole.broken_bonds}, file
    assert len(bonds) > 100  # the plate cracked, across the pieces' borders too
    # Nothing but the pieces, the .pvtu and no gathered .vtu.
    names = sorted(os.listdir(run / "frames"))
    assert len(names) == 7 * (ranks + 1) and not any(re.fullmatch(r"frame_\d{6}\.vtu", n) for n in names)


def test_postprocess_reads_a_frame_in_pieces_as_the_gathered_frame_bit_for_bit(prepared, runs):
    """postprocess's reader (meshio, piece by piece) opens a .pvtu and finds the gathered frame of the
    same run: points and every point array in global node order, and the broken bonds, bit for bit."""
    gathered = copy_case(prepared, "gathered_np2", lambda case: case["output"].update(parallel_frames="gathered"))
    assert solve(gathered, 2).returncode == 0
    assert listed(runs[2]) == [(t, f.replace(".vtu", ".pvtu")) for t, f in listed(gathered)]
    for (_, file), (_, pfile) in zip(listed(gathered), listed(runs[2])):
        whole, pieces = read_frame(str(gathered / file)), read_frame(str(runs[2] / pfile))
        assert np.array_equal(pieces.points, whole.points)
        assert sorted(pieces.point_data) == sorted(whole.point_data)
        for name, values in whole.point_data.items():
            assert pieces.point_data[name].dtype == values.dtype and np.array_equal(pieces.point_data[name], values), name
        assert (pieces.time, pieces.step) == (whole.time, whole.step)
        assert sorted(map(tuple, pieces.broken_bonds.tolist())) == sorted(map(tuple, whole.broken_bonds.tolist()))
    result = subprocess.run([PY, "-m", "postprocess", str(runs[2])], cwd=ROOT, capture_output=True, text=True,
                            timeout=600, env=dict(os.environ, PYTHONPATH=ROOT))
    assert result.returncode == 0, result.stderr


PV_SCRIPT = """
import sys
from paraview.simple import PVDReader, UpdatePipeline, servermanager
from paraview.vtk.numpy_interface import dataset_adapter as dsa
reader = PVDReader(FileName=sys.argv[1])
times = list(reader.TimestepValues)
for t in times:
    UpdatePipeline(time=t, proxy=reader)
    data = dsa.WrapDataObject(servermanager.Fetch(reader))
    ghost = data.PointData["vtkGhostType"]
    print("frame", t, data.GetNumberOfPoints(), int((ghost == 0).sum()))
"""


@pytest.mark.skipif(PVPYTHON is None, reason="no pvpython (ParaView): apt-get install paraview")
def test_paraview_opens_the_series_and_sees_every_node(runs, tmp_path):
    script = tmp_path / "count.py"
    script.write_text(PV_SCRIPT)
    result = subprocess.run([PVPYTHON, "--force-offscreen-rendering", str(script), str(runs[3] / "frames.pvd")],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    frames = [line.split() for line in result.stdout.splitlines() if line.startswith("frame ")]
    nodes = len(read_frame(str(runs["serial"] / listed(runs["serial"])[0][1])).points)
    assert len(frames) == 7
    for _, _, points, owned in frames:
        assert int(owned) == nodes  # every node once
        assert int(points) > nodes  # and the ghosts, marked


def test_a_checkpoint_in_pieces_continues_on_3_ranks(prepared, runs):
    def change(case):
        in_pieces(case)
        with_checkpoints(3.0e-4, 1.2e-4)(case)
    written = copy_case(prepared, "pieces_ckpt_np2", change)
    result = solve(written, 2, frames=None)
    assert result.returncode == 0, result.stderr
    # On 3 ranks, and on 1 (no mpirun; --parallel-frames gathered asked for in vain): the series goes on
    # in pieces, as the checkpoint records, with the uninterrupted run's values.
    for ranks, extra in ((3, None), (None, "gathered")):
        folder = prepared[0] / f"pieces_ckpt_np2_to_{ranks}"
        shutil.copytree(written, folder)
        result = restart(folder, ranks, frames=None) if ranks else restart_serially(folder, extra)
        assert result.returncode == 0, result.stderr
        assert restarted_at_step(folder) > 200
        assert history_without_wall_time(folder) == history_without_wall_time(written)  # the uninterrupted run's
        assert listed(folder) == listed(runs[3])
        for _, pfile in listed(folder):
            ids, data, _ = assembled(folder / pfile)
            ids3, data3, _ = assembled(runs[3] / pfile)
            assert ids.tolist() == ids3.tolist()
            for name in data:
                assert np.array_equal(data[name], data3[name]), (pfile, name)


def restart_serially(folder, frames):
    command = [SOLVER, str(folder / "case.json"), "--quiet", "--threads", "1", "--restart", str(folder / "checkpoint.bin"),
               "--parallel-frames", frames]
    return subprocess.run(command, capture_output=True, text=True, timeout=900)


def test_a_serial_checkpoint_continues_its_plain_series_on_2_ranks(prepared, runs):
    """A series of plain .vtu frames (a run on one rank) goes on as plain .vtu frames when it is
    continued on several ranks, whose default is pieces: the restart keeps the series' format."""
    def change(case):
        in_pieces(case)
        with_checkpoints(3.0e-4, 1.2e-4)(case)
    written = copy_case(prepared, "serial_ckpt", change)
    assert solve(written, None).returncode == 0
    folder = prepared[0] / "serial_ckpt_to_np2"
    shutil.copytree(written, folder)
    result = restart(folder, 2, frames=None)
    assert result.returncode == 0, result.stderr
    assert restarted_at_step(folder) > 200
    assert_same_run(written, folder)
