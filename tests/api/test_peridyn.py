"""peridyn, the Python API: load a case, change keys, run make's stages, read the results as arrays.
Runs the membrane case coarsened to 20 × 20 nodes and 0.1 ms (a second or two)."""
import os

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import peridyn
from common.paths import pdsolve
from pipeline.case import CaseError

SOLVER = pdsolve()


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
    # nothing was meshed or solved; .lock is the folder's lock, which make leaves in out/<case>/ too
    assert sorted(os.listdir(tmp_path / "bad")) == [".lock", "bad.yaml"]


def test_open_reads_a_finished_run(run):
    again = peridyn.open(run.out_dir)
    assert len(again) == 5 and np.array_equal(again.history["dt"], run.history["dt"])


# -- values and keys from a program (issue 36, item 13): no solver needed -----------------------

@pytest.fixture
def membrane():
    return peridyn.load(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"))


def test_numpy_scalars_and_arrays_are_written_as_plain_numbers(membrane, tmp_path):
    """PyYAML's safe dumper raised RepresenterError on numpy values, after writing part of the file."""
    membrane["time.end"] = np.float64(2.0e-3)
    membrane["output.history_every"] = np.int64(2)
    membrane["contact.self_contact"] = np.bool_(False)
    membrane["figures.times"] = np.linspace(0.0, 2.0e-3, 3)
    membrane.data["damping"] = np.float32(250.0)      # put into the data directly: made plain at write()
    path = membrane.write(str(tmp_path / "study.yaml"))
    text = open(path, encoding="utf-8").read()
    assert "!!python" not in text and "numpy" not in text
    again = peridyn.load(path)
    assert again["time.end"] == 2.0e-3 and type(again["time.end"]) is float
    assert again["output.history_every"] == 2 and again["contact.self_contact"] is False
    assert again["figures.times"] == [0.0, 1.0e-3, 2.0e-3] and again["damping"] == 250.0


def test_numpy_long_double_becomes_a_double_and_its_complex_is_refused(membrane):
    """longdouble.tolist() is a longdouble again: the conversion recursed until RecursionError."""
    membrane["time.end"] = np.longdouble(2.0e-3)
    assert membrane["time.end"] == 2.0e-3 and type(membrane["time.end"]) is float
    with pytest.raises(TypeError, match=r"^time\.end: a numpy complex\d+ cannot be written to a case file"):
        membrane["time.end"] = np.clongdouble(1.0)


def test_a_value_yaml_cannot_hold_leaves_no_file(membrane, tmp_path):
    membrane.data["time"]["end"] = object()
    with pytest.raises(TypeError, match=r"^time\.end: a builtins\.object cannot be written to a case file"):
        membrane.write(str(tmp_path / "study.yaml"))
    assert os.listdir(tmp_path) == []  # neither the case file nor a temporary one
    with pytest.raises(TypeError, match=r"^figures\.times\.1: a builtins\.complex cannot be written"):
        membrane["figures.times"] = [0.0, 1j]


@pytest.mark.parametrize("key, message", [
    ("boundary_conditions.3.set", "boundary_conditions.3.set: boundary_conditions has 1 entries (indices 0 to 0), "
                                  "no index 3; set the whole list to add entries"),
    ("time.end.x", "time.end.x: time.end is a number (0.01), not a section: it has no key 'x'"),
    ("boundary_conditions.set", "boundary_conditions.set: boundary_conditions is a list of 1 entries: give an "
                                "index, e.g. boundary_conditions.0"),
])
def test_a_bad_index_or_a_key_under_a_value_names_the_path(membrane, key, message):
    """Before: IndexError (index past the end) and TypeError/AttributeError (a key under a number)."""
    with pytest.raises(KeyError) as got:
        membrane[key] = 1.0
    assert got.value.args[0] == message
    with pytest.raises(KeyError) as got:
        membrane[key]
    assert got.value.args[0] == message
    assert membrane["time.end"] == 0.01 and len(membrane["boundary_conditions"]) == 1  # nothing changed
