"""Fast branching (δ = 2 mm instead of 1 mm, still m = 3; 43 µs): the C7 criteria of
validation/branching (tip speed below c_R, branching before the right edge, symmetry about the
notch line) and the energy balance with broken bonds, whose error falls
about 4× or more (asserted: > 3×) when the time step halves."""
import pytest

from validation import branching
from validation.common import Run
from validation.runner import run_case

DX = 2.0e-3 / 3.0
CHANGES = {"discretization": {"dx": DX, "horizon": 2.0e-3},
           "node_sets": {"top_band": {"layer": 2.0e-3}, "bottom_band": {"layer": 2.0e-3}},
           "boundary_conditions": [{"set": "top", "body_force": {"y": 2.0e6 / DX}},
                                   {"set": "bottom", "body_force": {"y": -2.0e6 / DX}}],
           "figures": {"times": [0.0, 4.3e-5]}}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out, _ = run_case("branching", str(tmp_path_factory.mktemp("branching")), CHANGES, figures=False)
    half = dict(CHANGES, time={"safety_factor": 0.4})
    out_half, _ = run_case("branching", str(tmp_path_factory.mktemp("branching_half_dt")), half, figures=False)
    return out, out_half


def test_c7_criteria(runs):
    rows = branching.checks(runs[0])
    assert all(r.passed for r in rows), "\n".join(r.row() for r in rows)
    # measured: 2000 m/s at most, branching at x = 72 mm
    run = Run(runs[0])
    assert 40.0e-3 < branching.branch_point(run) < 90.0e-3
    assert branching.mirror_agreement(run) >= 0.95


def test_pre_crack_cuts_the_notch_bonds(runs):
    run = Run(runs[0])
    assert run.history["broken_bonds"][0] > 0          # the notch's bonds are broken at t = 0
    assert run.history["broken_bond_energy"][0] == 0.0  # and held no energy
    assert run.history["broken_bond_energy"][-1] > 0.0


def test_energy_balance_with_breakage_converges_with_dt(runs):
    # KE + U + E_broken + damping work − W_ext. A bond's energy is booked at the critical stretch s0
    # it crossed (issue 16). Velocity Verlet, which pays only the first half-kick of the force of a
    # bond that breaks, removes ½ c s_n s_(n+1) from the body, s_n ≤ s0 < s_(n+1): the mismatch of one
    # bond is O((s_(n+1) − s_n)²) = O(Δt²), so halving Δt cuts it about 4× where booking at s_(n+1)
    # (before issue 16: an O(Δt) mismatch) only halved it. Measured: 0.070 % → 0.0124 % (×5.6); the
    # old booking gave 1.14 % → 0.53 % (×2.2) on the same runs.
    full, _ = branching.energy_balance(Run(runs[0]))
    half, _ = branching.energy_balance(Run(runs[1]))
    assert full < 0.002
    assert full / half > 3.0


# make validate's branching-lps is this run at the case's δ = 1 mm, judged by the same checks.
@pytest.mark.slow
def test_c7_criteria_with_lps(tmp_path):
    """cases/branching/lps.yaml (LPS, glass's ν = 0.22) at δ = 2 mm: the same C7 criteria, with the
    Rayleigh speed of ν = 0.22 (3156 m/s, plane stress) as the bound on the tip speed."""
    out, _ = run_case("branching", str(tmp_path), CHANGES, figures=False, config="lps")
    run = Run(out)
    assert run.case["blocks"][0]["model"] == "lps"
    assert branching.rayleigh_speed(run) == pytest.approx(3156.2, abs=0.5)
    rows = branching.checks(out, case="branching-lps")
    assert all(r.passed for r in rows), "\n".join(r.row() for r in rows)
    assert 40.0e-3 < branching.branch_point(run) < 90.0e-3
