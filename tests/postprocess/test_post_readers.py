"""Readers of the solver output: history.csv, frames.pvd and one frame .vtu (formats.md §4)."""
import os
import shutil

import meshio
import numpy as np
import pytest

import synthetic_output as synth
from postprocess import HISTORY_COLUMNS, PostprocessError, read_frame, read_history, read_series


# ---------------------------------------------------------------- history.csv

def test_history_returns_every_column_exactly(run2d):
    history = read_history(str(run2d.out / "history.csv"))
    assert list(history) == list(HISTORY_COLUMNS)
    for name in HISTORY_COLUMNS:
        assert np.array_equal(history[name], run2d.history[name]), name
    for name in ("step", "iterations", "rejected", "broken_bonds"):
        assert history[name].dtype == np.int64
    # the analytic columns themselves, not only what we wrote: KE = cos²(ωt) e^{-λt}
    t = history["time"]
    assert np.array_equal(history["kinetic_energy"], np.cos(synth.OMEGA * t) ** 2 * np.exp(-synth.DECAY * t))
    assert history["kinetic_energy"][0] == 1.0 and history["step"][-1] == len(t) - 1


def test_history_tolerates_blank_lines_spaces_and_extra_columns(tmp_path):
    path = tmp_path / "history.csv"
    path.write_text(synth.HISTORY_HEADER + ",extra\n"
                    "0, 0.0, 0.0, 1, 0, 1.5, 0.0, 0.0, 0.0, 0, 0.0, 7\n\n"
                    "1,1e-6,1e-6,3.0,0,1.25,0.25,0,0,2,0.01,8\r\n")
    history = read_history(str(path))
    assert history["iterations"].tolist() == [1, 3]
    assert history["kinetic_energy"].tolist() == [1.5, 1.25]
    assert history["extra"].tolist() == [7.0, 8.0]


@pytest.mark.parametrize("row, what", [
    ("5,1e-6,1e-6,1,0,1.0,0.0,0.0,0.0,0", "10 fields, the header has 11"),
    ("5,1e-6,1e-6,1,0,one,0.0,0.0,0.0,0,0.1", "column 'kinetic_energy': 'one' is not a number"),
    ("5,1e-6,1e-6,2.5,0,1.0,0.0,0.0,0.0,0,0.1", "column 'iterations': '2.5' is not a whole number"),
    ("5,1e-6,1e-6,1,0,1.0,0.0,0.0,0.0,0,0.1,9", "12 fields, the header has 11"),
])
def test_history_rejects_a_malformed_row_naming_file_and_line(run2d, row, what):
    path = run2d.out / "history.csv"
    lines = path.read_text().splitlines()
    lines.insert(4, row)  # becomes line 5 of the file
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(PostprocessError) as error:
        read_history(str(path))
    assert f"{path}:5:" in str(error.value)
    assert what in str(error.value)


def test_history_names_a_missing_column(tmp_path):
    path = tmp_path / "history.csv"
    header = synth.HISTORY_HEADER.replace(",damping_work", "")
    path.write_text(header + "\n" + ",".join(["0"] * 10) + "\n")
    with pytest.raises(PostprocessError, match=r"history\.csv:1: header lacks column\(s\) damping_work"):
        read_history(str(path))


def test_history_empty_header_only_and_missing_file(tmp_path):
    empty = tmp_path / "empty.csv"
    empty.write_text("\n")
    with pytest.raises(PostprocessError, match="empty.csv: empty file"):
        read_history(str(empty))
    header_only = tmp_path / "header.csv"
    header_only.write_text(synth.HISTORY_HEADER + "\n")
    with pytest.raises(PostprocessError, match="header.csv: a header but no data rows"):
        read_history(str(header_only))
    with pytest.raises(PostprocessError, match=r"nothing\.csv: no such file; run the solver first"):
        read_history(str(tmp_path / "nothing.csv"))


# ---------------------------------------------------------------- frames.pvd

def test_series_lists_frames_in_time_order_with_absolute_paths(run2d):
    series = read_series(str(run2d.out / "frames.pvd"))
    assert [t for t, _ in series] == run2d.times.tolist()
    assert [p for _, p in series] == [str(run2d.out / f"frames/frame_{k:06d}.vtu") for k in range(len(run2d.times))]


def test_series_sorts_a_collection_listed_out_of_order(run2d):
    entries = [(float(t), f"frames/frame_{k:06d}.vtu") for k, t in enumerate(run2d.times)]
    synth.write_pvd(run2d.out / "frames.pvd", entries[::-1])
    series = read_series(str(run2d.out / "frames.pvd"))
    assert [t for t, _ in series] == sorted(run2d.times.tolist())
    assert series[0][1].endswith("frame_000000.vtu")


def test_series_errors(run2d, tmp_path):
    pvd = run2d.out / "frames.pvd"
    os.unlink(run2d.out / "frames" / "frame_000003.vtu")
    with pytest.raises(PostprocessError, match=r"lists frames/frame_000003\.vtu, which does not exist"):
        read_series(str(pvd))
    pvd.write_text(pvd.read_text()[:-30])  # truncated XML
    with pytest.raises(PostprocessError, match=r"frames\.pvd:\d+:\d+: not well-formed XML"):
        read_series(str(pvd))
    synth.write_pvd(pvd, [])
    with pytest.raises(PostprocessError, match="lists no frames"):
        read_series(str(pvd))
    with pytest.raises(PostprocessError, match="no such file; run the solver first"):
        read_series(str(tmp_path / "frames.pvd"))


def test_series_lists_frames_in_pieces_and_a_broken_pvtu_is_named(tmp_path):
    """output.parallel_frames: pieces (an MPI run's default) lists .pvtu files: the series lists
    them, and reading one that is not a PUnstructuredGrid, or names no piece, says which file."""
    (tmp_path / "frames").mkdir()
    (tmp_path / "frames" / "frame_000000.pvtu").write_text("<VTKFile/>")
    synth.write_pvd(tmp_path / "frames.pvd", [(0.0, "frames/frame_000000.pvtu")])
    assert read_series(str(tmp_path / "frames.pvd")) == [(0.0, str(tmp_path / "frames" / "frame_000000.pvtu"))]
    with pytest.raises(PostprocessError, match=r"frame_000000\.pvtu: not a VTK PUnstructuredGrid"):
        read_frame(str(tmp_path / "frames" / "frame_000000.pvtu"))
    (tmp_path / "frames" / "frame_000000.pvtu").write_text('<VTKFile type="PUnstructuredGrid"/>')
    with pytest.raises(PostprocessError, match=r"frame_000000\.pvtu: names no piece"):
        read_frame(str(tmp_path / "frames" / "frame_000000.pvtu"))


# ---------------------------------------------------------------- one frame

def test_frame_returns_points_point_data_and_broken_bonds_exactly(run2d):
    k = len(run2d.times) - 1
    frame = read_frame(str(run2d.out / f"frames/frame_{k:06d}.vtu"))
    assert np.array_equal(frame.points, run2d.points)
    assert np.array_equal(frame.displacement, run2d.displacements[k])
    assert np.array_equal(frame.damage, run2d.damages[k])
    assert frame.point_data["block"].dtype == np.int32
    assert frame.broken_bonds.shape == (k - 1, 2)
    assert np.array_equal(frame.broken_bonds, run2d.broken[k])
    assert frame.time == run2d.times[k] and frame.step == 8 * k


def test_frame_without_broken_bonds_has_an_empty_bond_list(run2d):
    frame = read_frame(str(run2d.out / "frames/frame_000000.vtu"))
    assert frame.broken_bonds.shape == (0, 2)
    assert np.all(frame.damage == 0.0)


def test_frame_written_by_meshio_reads_the_same(run2d, tmp_path):
    """Independence from one writer: meshio's own (zlib-compressed) VTU gives the same frame."""
    k = 4
    mine = read_frame(str(run2d.out / f"frames/frame_{k:06d}.vtu"))
    n = len(mine.points)
    mesh = meshio.Mesh(mine.points, [("vertex", np.arange(n).reshape(-1, 1)), ("line", mine.broken_bonds)],
                       point_data=mine.point_data,
                       cell_data={"broken_bond": [np.zeros(n, np.uint8), np.ones(len(mine.broken_bonds), np.uint8)]},
                       field_data={"TIME": np.array([mine.time]), "step": np.array([mine.step])})
    path = tmp_path / "meshio.vtu"
    meshio.write(str(path), mesh, binary=True)
    theirs = read_frame(str(path))
    assert np.array_equal(theirs.points, mine.points)
    assert np.array_equal(theirs.displacement, mine.displacement)
    assert np.array_equal(theirs.damage, mine.damage)
    assert np.array_equal(theirs.broken_bonds, mine.broken_bonds)
    assert theirs.time is None  # meshio 5.0 does not write FieldData: TIME is optional to the reader


def test_frame_errors_name_the_file(run2d, tmp_path):
    bad = tmp_path / "frame.vtu"
    shutil.copy(run2d.out / "frames/frame_000002.vtu", bad)
    bad.write_bytes(bad.read_bytes()[:200])  # truncated
    with pytest.raises(PostprocessError, match=f"{bad}: cannot read as VTK XML UnstructuredGrid"):
        read_frame(str(bad))
    no_damage = tmp_path / "no_damage.vtu"
    synth.write_vtu(no_damage, run2d.points, {"displacement": run2d.displacements[1]}, {}, np.zeros((0, 2)))
    with pytest.raises(PostprocessError, match=f"{no_damage}: point data lacks damage"):
        read_frame(str(no_damage))
