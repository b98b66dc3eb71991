"""Compact frames (output.precision, output.compression, output.fields; pipeline/formats.md §4):
meshio reads a float32 + zlib frame and a float64 raw frame of the same run with the same arrays,
equal to float32 round-off, and the history is the same bytes either way (frames change format only)."""
import json
import os
import shutil
import subprocess

import meshio
import numpy as np
import pytest
import yaml

from e2e_support import ROOT, SOLVER, new_case_folder, run_stages  # noqa: E402


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "compact", "membrane")
    shutil.copy(os.path.join(ROOT, "cases", "membrane", "membrane.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    case["time"]["end"] = 1.0e-3
    case["output"] = {"every_time": 5.0e-4}
    case["figures"]["times"] = [0.0, 1.0e-3]
    yaml_path = case_dir / "membrane.yaml"
    yaml_path.write_text(yaml.safe_dump(case))
    compact = work / "out" / "compact"
    run_stages(yaml_path, case_dir / "membrane.geo", compact)  # defaults: float32, zlib
    exact = work / "out" / "exact"
    exact.mkdir(parents=True)
    shutil.copy(compact / "nodes.vtu", exact)
    resolved = json.loads((compact / "case.json").read_text())
    resolved["output"].update(precision="float64", compression="none")
    (exact / "case.json").write_text(json.dumps(resolved))
    subprocess.run([SOLVER, str(exact / "case.json"), "--quiet"], check=True, timeout=600)
    return compact, exact


def test_meshio_reads_both_encodings_with_the_same_arrays(two_runs):
    compact, exact = two_runs
    a = meshio.read(compact / "frames" / "frame_000002.vtu")
    b = meshio.read(exact / "frames" / "frame_000002.vtu")
    head = (compact / "frames" / "frame_000002.vtu").read_bytes()[:400]
    assert b'compressor="vtkZLibDataCompressor"' in head
    assert set(a.point_data) == set(b.point_data) == {"displacement", "velocity", "damage", "block"}
    assert a.point_data["displacement"].dtype == np.float32 and b.point_data["displacement"].dtype == np.float64
    assert a.points.dtype == np.float64 and np.array_equal(a.points, b.points)  # reference points exact
    for name in ("displacement", "velocity", "damage"):
        wide = b.point_data[name]
        if name != "damage":  # the membrane cannot break: its damage is 0 everywhere
            assert np.any(wide != 0.0), name  # a test of something: the membrane moves
        assert np.array_equal(a.point_data[name], wide.astype(np.float32)), name  # round to nearest float32
    assert np.array_equal(a.point_data["block"], b.point_data["block"])
    assert [c.type for c in a.cells] == [c.type for c in b.cells]
    assert float(np.ravel(a.field_data["TIME"])[0]) == float(np.ravel(b.field_data["TIME"])[0])
    assert os.path.getsize(compact / "frames" / "frame_000002.vtu") < \
        0.5 * os.path.getsize(exact / "frames" / "frame_000002.vtu")


def test_history_is_the_same_bytes_but_the_wall_time(two_runs):
    compact, exact = two_runs
    strip = lambda p: [",".join(line.split(",")[:10]) for line in p.read_text().splitlines()]  # noqa: E731
    assert strip(compact / "history.csv") == strip(exact / "history.csv")


def test_output_fields_chooses_the_point_arrays(two_runs, tmp_path):
    compact, _ = two_runs
    shutil.copy(compact / "nodes.vtu", tmp_path)
    resolved = json.loads((compact / "case.json").read_text())
    resolved["output"]["fields"] = ["damage", "displacement"]
    resolved["time"]["end"] = resolved["output"]["every_time"]  # frame_000001 is the last: half the steps
    (tmp_path / "case.json").write_text(json.dumps(resolved))
    subprocess.run([SOLVER, str(tmp_path / "case.json"), "--quiet"], check=True, timeout=600)
    mesh = meshio.read(tmp_path / "frames" / "frame_000001.vtu")
    assert list(mesh.point_data) == ["displacement", "damage"]  # the frame's own order
