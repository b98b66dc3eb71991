"""The solver on a disk that fills during the run (issue 17, item 6): exit 3 with "disk full
writing <file>: free N MB and run make again", no .part file left, history.csv ending with a whole
row (every row has the header's columns), frames.pvd listing only frames that exist.

Before: exit 1 ("bad input"), history.csv cut mid-row while the message said the rows were
complete, .part files left. The full disk is a real one: a small tmpfs (tests/disk_full.py).
"""
import json
import os
import re
import shutil

import pytest

from e2e_support import ROOT, SOLVER, new_case_folder, prepare_stages  # noqa: E402

from tests.disk_full import run_on_small_disk


@pytest.fixture(scope="module")
def prepared(tmp_path_factory):
    import yaml
    work, case_dir = new_case_folder(tmp_path_factory, "diskfull", "membrane")
    shutil.copy(os.path.join(ROOT, "cases", "membrane", "membrane.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    case["discretization"]["dx"] = 0.002
    case["node_sets"]["clamped"]["layer"] = 0.006
    case["time"]["end"] = 2.0e-3
    case["output"] = {"every_time": 2.0e-3 / 40}
    (case_dir / "membrane.yaml").write_text(yaml.safe_dump(case))
    out = work / "prepared"
    prepare_stages(case_dir / "membrane.yaml", case_dir / "membrane.geo", out)
    resolved = json.loads((out / "case.json").read_text())
    resolved["output_dir"] = "out"
    (out / "case.json").write_text(json.dumps(resolved, indent=1))
    return out


@pytest.mark.parametrize("size_kb, frames", [
    (40, 40),    # full early, while writing a frame
    (200, 40),   # later
    (100, 1),    # one frame at the start, then history.csv fills the disk with a write cut mid-row
])
def test_disk_full_during_the_run(prepared, tmp_path, size_kb, frames):
    kept = tmp_path / "kept"
    kept.mkdir()
    resolved = json.loads((prepared / "case.json").read_text())
    resolved["output"]["every_time"] = resolved["time"]["end"] / frames
    (tmp_path / "case.json").write_text(json.dumps(resolved, indent=1))
    os.symlink(prepared / "nodes.vtu", tmp_path / "nodes.vtu")
    (tmp_path / "out").mkdir()
    code, _, err, left = run_on_small_disk(tmp_path / "out", [SOLVER, str(tmp_path / "case.json"), "--quiet",
                                                              "--threads", "1"], size_kb=size_kb, keep=kept)
    assert code == 3, err
    match = re.search(r"disk full writing (\S+): free (\d+) MB and run make again", err)
    assert match, err
    assert match.group(1).startswith(str(tmp_path / "out"))
    if frames == 1:
        assert match.group(1).endswith("history.csv"), err
    assert "internal error" not in err and "(disk full?)" not in err
    assert not [name for name in left if name.endswith(".part")], left
    frames = kept / "frames"
    assert not [p for p in frames.iterdir() if p.name.endswith(".part")]
    history = (kept / "history.csv").read_text()
    assert history.endswith("\n")
    rows = history.splitlines()
    assert all(row.count(",") == rows[0].count(",") for row in rows), rows[-2:]
    pvd = (kept / "frames.pvd").read_text()
    for name in re.findall(r'file="([^"]+)"', pvd):
        assert (kept / name).is_file(), name
