"""Fast three_point_bending (validation/three_point_bending.py): the same steel SENB beam in LPS
(ν = 0.29), stopped at 0.42 ms, before any bond breaks: the stiffness of the beam's axis against
Timoshenko's beam plus the notch's compliance (Irwin–Kies with ASTM E399's K), the check
`make validate` applies to the full run."""
import numpy as np
import pytest

from validation import three_point_bending as tpb
from validation.common import Run
from validation.runner import run_case


def test_e399_f_is_srawleys_formula():
    # ASTM E399 (S/W = 4) tabulates f(0.45) = 2.29, f(0.50) = 2.66, f(0.55) = 3.14
    assert tpb.e399_f([0.45, 0.50, 0.55]) == pytest.approx([2.29, 2.66, 3.14], abs=0.006)


def test_elastic_stiffness_before_cracking(tmp_path):
    out, _ = run_case("three_point_bending", str(tmp_path), {"time": {"end": 4.2e-4}}, figures=False)
    run = Run(out)
    assert run.case["blocks"][0]["model"] == "lps" and run.case["blocks"][0]["poisson_ratio"] == 0.29
    assert run.history["broken_bonds"][-1] == run.history["broken_bonds"][0]     # only the notch
    m = tpb.measure(out)
    k = m["spec"].stiffness()
    assert m["frames"] >= 5
    assert m["k_axis"] == pytest.approx(k, rel=tpb.STIFFNESS_TOLERANCE)
    # the axis deflection leaves out the patches' indentation: the load point is softer
    assert m["k_load"] < m["k_axis"]
    assert np.isfinite(m["spec"].lefm_peak())
