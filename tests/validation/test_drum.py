"""Fast drum (dx = 1 mm: the free span is 50 dx instead of 100; 4 periods): the fundamental
frequency of the pre-tensioned membrane within 3 % of (√2/(2L))·√(T/(ρh)), no energy drift without
damping, the clamping frame holding the pre-strained edge, and the pre-strain itself exact: the
initial strain energy is the lattice sum ¼·c·ε0²·Σ_i V_i Σ_j V_j |ξ_ij| (every bond stretched by ε0)."""
import numpy as np
import pytest
from scipy.spatial import cKDTree

from validation import drum
from validation.common import Run
from validation.runner import run_case

DX = 1.0e-3
CHANGES = {"geometry": {"parameters": {"w": 3 * DX}}, "discretization": {"dx": DX},
           "node_sets": {"clamped": {"layer": 3 * DX}}, "time": {"end": 4.7e-3},
           "figures": {"times": [0.0, 4.7e-3]}}


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    out_dir, _ = run_case("drum", str(tmp_path_factory.mktemp("drum")), CHANGES, figures=False)
    return out_dir


def test_fundamental_frequency_energy_and_clamp(out):
    rows = drum.checks(out)
    assert all(r.passed for r in rows), "\n".join(r.row() for r in rows)
    run = Run(out)
    t, q = drum.modal_coordinate(run)
    ratio = drum.zero_crossing_frequency(t, q)[0] / drum.theory_frequency(run)
    # measured 0.979 at L/dx = 50 (0.9959 at L/dx = 100, the full case): the nonlocal clamp
    # lengthens the span by about dx, the lattice sum (C1) stiffens it by 1.025
    assert 0.97 < ratio < 0.99


def test_pre_strain_energy_is_the_lattice_sum(out):
    run = Run(out)
    eps = drum.pre_strain(run)
    import meshio
    nodes = meshio.read(f"{out}/nodes.vtu")
    volume = nodes.point_data["volume"]
    pairs = cKDTree(run.x[:, :2]).query_pairs(run.horizon, output_type="ndarray")
    length = np.linalg.norm(run.x[pairs[:, 0], :2] - run.x[pairs[:, 1], :2], axis=1)
    h, E = run.case["thickness"], run.case["blocks"][0]["youngs_modulus"]
    c = 9.0 * E / (np.pi * h * run.horizon ** 3)           # plane stress (docs/theory.md T2)
    # each pair once: ½·c·s²·|ξ|·V_i·V_j (= ¼ summed over both ends), s = ε0 for every bond
    expected = 0.5 * c * eps ** 2 * np.sum(length * volume[pairs[:, 0]] * volume[pairs[:, 1]])
    assert run.history["strain_energy"][0] == pytest.approx(expected, rel=1e-9)
    # and every node starts at u = ε0·x, y alike (the frame included, its fields stored as float32
    # by default, output.precision: so equal to float32 rounding, half an ulp: 2⁻²⁴ relative)
    u0 = run.frame(0).displacement
    assert np.allclose(u0[:, :2], eps * run.x[:, :2], rtol=2.0 ** -24, atol=1e-15)


def test_energy_error_falls_4x_when_dt_halves(tmp_path_factory):
    # docs/theory.md C4 without breakage: velocity Verlet's energy error is O(Δt²), bounded, no drift.
    # Coarse drum (dx = 2 mm), 2 periods; measured 2.30e-5, 5.74e-6 (and 1.43e-6 at 0.2) of KE(0).
    dx = 2.0e-3
    errors = []
    for safety in (0.8, 0.4):
        changes = {"geometry": {"parameters": {"w": 3 * dx}}, "discretization": {"dx": dx},
                   "node_sets": {"clamped": {"layer": 3 * dx}},
                   "time": {"end": 2.4e-3, "safety_factor": safety}, "output": {"history_every": 1},
                   "figures": {"times": [0.0, 2.4e-3]}}
        out, _ = run_case("drum", str(tmp_path_factory.mktemp(f"drum_dt{safety}")), changes, figures=False)
        errors.append(drum.energy_drift(Run(out))[0])
    assert errors[0] < 1e-4
    assert 3.5 < errors[0] / errors[1] < 4.5
