"""End to end: contact between bodies and fragments on several MPI ranks (issue 15).

The short impact of tests/e2e/test_impact.py (cases/impact at dx = 0.25 mm, a 1 mm gap; here the
first 20 µs: the disk strikes at about 5 µs and cracks the plate) runs without mpirun, then under
`mpiexec --oversubscribe` on 2 and 3 ranks with one thread each and on 2 ranks with two. The
contact pairs of an owned node may belong to any rank and move with the bodies, so each Verlet-list
build finds its contact ghosts anew (forces/contact_on_piece). Frames, frames.pvd and history.csv
(but for its wall_time column; contact_energy and contact_rebuilds included) are byte-identical to
the serial run's. A checkpoint written on 2 ranks, between two list builds, continues on 3 ranks
and on 1 as the uninterrupted run, byte for byte.
"""
import os
import re
import shutil

import pytest
import yaml

from e2e_support import ROOT, new_case_folder, prepare_stages  # noqa: E402
from test_impact import coarsen
from test_mpi_checkpoint import assert_same_run, restart, restarted_at_step
from test_mpi_ranks import copy_case, history_without_wall_time, pytestmark, solve  # noqa: F401

END = 2.0e-5


@pytest.fixture(scope="module")
def prepared(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "mpi_contact", "impact")
    shutil.copy(os.path.join(ROOT, "cases", "impact", "impact.geo"), case_dir)
    with open(os.path.join(ROOT, "cases", "impact", "impact.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    coarsen(case)
    case["time"]["end"] = END
    case["output"] = {"every_time": 5.0e-6, "history_every": 5}
    yaml_path = case_dir / "impact.yaml"
    yaml_path.write_text(yaml.safe_dump(case))
    out = work / "prepared"
    prepare_stages(yaml_path, case_dir / "impact.geo", out)
    return work, out


def column(history, name):
    header = history[0].split(",")
    return [float(line.split(",")[header.index(name)]) for line in history[1:]]


@pytest.fixture(scope="module")
def runs(prepared):
    folders = {}
    for name, ranks, threads in (("serial", None, 1), ("np2", 2, 1), ("np3", 3, 1), ("np2t2", 2, 2)):
        folder = copy_case(prepared, name)
        result = solve(folder, ranks, threads)
        assert result.returncode == 0, f"{name}: {result.stdout}\n{result.stderr}"
        folders[name] = folder
    return folders


@pytest.mark.parametrize("name", ["np2", "np3", "np2t2"])
def test_impact_on_ranks_equals_the_serial_run_byte_for_byte(runs, name):
    serial, run = runs["serial"], runs[name]
    history = history_without_wall_time(serial)
    # The scene did what it is meant to test: the bodies touched, the list was rebuilt now and
    # then (every rank together), the plate cracked.
    assert max(column(history, "contact_energy")) > 0.0
    rebuilds = column(history, "contact_rebuilds")
    assert 5 < rebuilds[-1] < column(history, "step")[-1] / 3
    assert column(history, "broken_bonds")[-1] > 100
    assert history_without_wall_time(run) == history
    assert (run / "frames.pvd").read_bytes() == (serial / "frames.pvd").read_bytes()
    frames = sorted(os.listdir(serial / "frames"))
    assert len(frames) == 5  # t = 0 and every 5 µs to 20 µs
    assert sorted(os.listdir(run / "frames")) == frames
    for frame in frames:
        assert (run / "frames" / frame).read_bytes() == (serial / "frames" / frame).read_bytes(), frame
    # run.log: the same builds and pairs as the serial run, and what the contact ghosts cost.
    pairs = re.search(r"contact: (\d+) Verlet-list builds in (\d+) steps, .* (\d+) pairs in the last list",
                      (serial / "run.log").read_text()).groups()
    log = (run / "run.log").read_text()
    assert re.search(r"contact: (\d+) Verlet-list builds in (\d+) steps, .* (\d+) pairs in the last list", log).groups() == pairs
    ranks = 3 if name == "np3" else 2
    contact = re.findall(r"rank (\d) contact: (\d+) contact ghosts .*?; per step: ([0-9.e+-]+) box exchanges sending "
                         r"([0-9.e+-]+) bytes, ([0-9.e+-]+) contact halo exchanges", log)
    assert [c[0] for c in contact] == [str(r) for r in range(ranks)], log
    for _, _, boxes, _, halos in contact:
        assert 0.0 < float(boxes) < 1.0   # builds: now and then
        assert float(halos) >= 1.0         # the ghosts' displacements: every force evaluation


def test_a_checkpoint_on_2_ranks_continues_on_3_and_on_1_bitwise(prepared):
    def change(case):
        case["output"]["restart_every_time"] = 0.55 * END  # one checkpoint, after the impact
    reference = copy_case(prepared, "ckpt_reference", change)
    assert solve(reference, None).returncode == 0
    written = copy_case(prepared, "ckpt_np2", change)
    result = solve(written, 2)
    assert result.returncode == 0, result.stderr
    assert_same_run(reference, written)
    history = history_without_wall_time(reference)
    for name, ranks in (("ckpt_np2_to_np3", 3), ("ckpt_np2_to_serial", None)):
        folder = prepared[0] / name
        shutil.copytree(written, folder)
        result = restart(folder, ranks)
        assert result.returncode == 0, f"{name}: {result.stderr}"
        step = restarted_at_step(folder)
        assert step > 0
        # The restart came after the bodies touched and before the last build (so the restored
        # list was used, and then rebuilt on the new rank count).
        steps, rebuilds = column(history, "step"), column(history, "contact_rebuilds")
        at = max(k for k, s in enumerate(steps) if s <= step)
        assert max(column(history, "contact_energy")[: at + 1]) > 0.0
        assert rebuilds[-1] > rebuilds[at]
        assert_same_run(reference, folder)
