"""Fast traction (dx = 0.5 mm instead of 0.25 mm, 1 ms): the dog-bone breaks inside its gauge
section, across the load, and the pulled grip's reaction (history.csv reaction_right_fx, from
output.reactions) rises linearly, peaks and falls to almost nothing."""
import os

import numpy as np
import pytest

from validation import traction
from validation.common import Run
from validation.runner import run_case

CHANGES = {"discretization": {"dx": 5.0e-4}, "time": {"end": 1.0e-3},
           "output": {"every_time": 2.0e-5, "history_every": 10}, "figures": {"times": [0.0, 1.0e-3]}}


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    out, _ = run_case("traction", str(tmp_path_factory.mktemp("traction")), CHANGES, figures=True)
    return out


def test_cracks_in_the_gauge_across_the_load(out):
    rows = traction.checks(out)
    assert all(r.passed for r in rows), "\n".join(r.row() for r in rows)
    assert len(traction.crack_clusters(Run(out))) >= 1


def test_force_displacement_curve(out):
    run = Run(out)
    u, force = traction.force_curve(run)
    peak = int(np.argmax(force))
    # Before the peak the specimen is elastic: the force is proportional to the grip displacement
    # (secant stiffness at a quarter and at three quarters of the peak agree to 5 %).
    q1 = np.searchsorted(u, 0.25 * u[peak])
    q3 = np.searchsorted(u, 0.75 * u[peak])
    assert force[q1] / u[q1] == pytest.approx(force[q3] / u[q3], rel=0.05)
    assert 150.0 < force[peak] < 400.0       # measured 256 N (narrowest section 10 mm × 1 mm: 25.6 MPa)
    assert abs(force[-1]) < 0.1 * force[peak]
    assert os.path.isfile(os.path.join(out, "figures", "reaction_force.png"))
