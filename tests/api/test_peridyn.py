"""peridyn, the Python API: load a case, change keys, run make's stages, read the results as arrays.
Runs the membrane case coarsened to 20 × 20 nodes and 0.1 ms (a second or two)."""
import os
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

import peridyn  # noqa: E402
from pipeline.case import CaseError  # noqa: E402

SOLVER = os.environ.get("PDSOLVE", os.path.join(ROOT, "build", "solver", "pdsolve"))


@pytest.fixture(scope="module")
def small():
    if not os.path.isfile(SOLVER):
        pytest.fail(f"{SOLVER} is missing: build it with `make solver`")
    case = peridyn.load(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"))
    case["discretization.dx"] = 2.5e-3
    case["node_sets.clamped.layer"] = 7.5e-3
    case["time.end"] = 1.0e-4
    case["output.every_time"] = 2.5e-5
    case["figures.times"] = None
    return case


@pytest.fixture(scope="module")
def run(small, tmp_path_factory):
    return small.run(str(tmp_path_factory.mktemp("api") / "coarse"), threads=1)


def test_keys_read_and_change_by_dotted_path(small):
    assert small["materials.membrane.density"] == 1200.0
    assert small["time.end"] == 1.0e-4
    assert small["boundary_conditions.0.set"] == "clamped"
    with pytest.raises(KeyError, match="time.ends: not in the case file"):
        small["time.ends"]


def test_a_run_goes_through_make_s_stages_with_the_changed_keys(run):
    case = run.case
    assert case["case"] == "coarse" and case["grid_spacing"] == 2.5e-3 and case["time"]["end"] == 1.0e-4
    names = set(os.listdir(run.out_dir))
    assert {"coarse.yaml", "mesh.msh", "nodes.vtu", "case.json", "history.csv", "history.json", "frames.pvd",
            "run.log", "figures", "gmsh"} <= names
    assert len(run.frame(0).points) == 20 * 20


def test_history_and_frames_are_numpy_arrays_equal_to_the_files(run):
    history = run.history
    assert history["time"][-1] == pytest.approx(1.0e-4, rel=1e-12)
    with open(os.path.join(run.out_dir, "history.csv")) as stream:
        rows = stream.read().splitlines()
    assert list(history) == rows[0].split(",") and len(history["step"]) == len(rows) - 1
    last = rows[-1].split(",")
    assert history["kinetic_energy"][-1] == float(last[rows[0].split(",").index("kinetic_energy")])
    assert np.allclose(run.times, [0.0, 2.5e-5, 5e-5, 7.5e-5, 1e-4], rtol=1e-9, atol=0)
    frame = run.frame(-1)
    assert frame.displacement.shape == (400, 3) and frame.damage.shape == (400,)
    # the initial velocity of the centre set moved it out of plane; the clamped edge stays put
    centre = run.frame_at(1e-4).displacement[:, 2]
    assert centre.max() > 0 and np.all(run.frame(0).displacement == 0)
    assert [f.time for f in run.frames()] == pytest.approx(list(run.times))


def test_a_bad_key_fails_before_any_work_naming_the_file_and_key(small, tmp_path):
    bad = small.copy()
    bad["time.safety_factr"] = 0.5
    with pytest.raises(CaseError, match=r"bad.yaml:\d+: time.safety_factr: unknown key \(did you mean 'safety_factor'\?\)"):
        bad.run(str(tmp_path / "bad"))
    assert sorted(os.listdir(tmp_path / "bad")) == ["bad.yaml"]  # nothing was meshed or solved


def test_open_reads_a_finished_run(run):
    again = peridyn.open(run.out_dir)
    assert len(again) == 5 and np.array_equal(again.history["dt"], run.history["dt"])
