"""Fast plate_with_hole (dx = 0.5 mm instead of 0.25 mm, loaded twice as fast, 0.45 ms): the
Kirsch concentration before breakage and the crack directions, checked by validation/plate_with_hole."""
import pytest

from validation import plate_with_hole
from validation.runner import run_case

CHANGES = {
    "discretization": {"dx": 5.0e-4},
    "node_sets": {"left": {"layer": 1.5e-3}, "right": {"layer": 1.5e-3}},
    "boundary_conditions": [{"set": "left", "velocity": {"x": [[0.0, 0.0], [1.0e-4, -0.5]]}},
                            {"set": "right", "velocity": {"x": [[0.0, 0.0], [1.0e-4, 0.5]]}}],
    "time": {"end": 4.5e-4},
    "output": {"every_time": 1.0e-5, "history_every": 10},
    "figures": {"times": [0.0, 4.5e-4]},
}


@pytest.fixture(scope="module")
def rows(tmp_path_factory):
    out, _ = run_case("plate_with_hole", str(tmp_path_factory.mktemp("pwh")), CHANGES, figures=False)
    return {r.quantity.split(" at ")[0].split(":")[0]: r for r in plate_with_hole.checks(out)}


def test_kirsch_concentration_before_breakage(rows):
    # Measured 2.62 at this resolution (hole radius 10 dx); 2.93 at the case's 20 dx.
    row = rows["edge/far-field strain ε_xx"]
    assert 2.55 <= row.got <= 3.45, row.row()


def test_cracks_start_and_run_perpendicular_to_the_load(rows):
    assert rows["crack initiation"].passed and rows["crack initiation"].got <= 10.0
    assert rows["crack path"].passed and rows["crack path"].got <= 15.0
