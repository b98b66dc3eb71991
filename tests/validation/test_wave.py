"""Fast wave checks (validation/wave.py, docs/theory.md C2) on the 1D chain (one row of lattice
nodes): a driven sinusoid's phase speed matches the discrete dispersion relation with velocity
Verlet's phase to 0.1 % (a shorter bar than `make validate`: 1 m), and a Gaussian pulse follows
d'Alembert's transport with an error that falls about 4× when δ halves at m = 3."""
import warnings

import pytest

from validation import wave
from validation.common import Run
from validation.runner import run_case


@pytest.fixture(scope="module")
def sinusoid(tmp_path_factory):
    changes, omega = wave.sinusoid_changes(dx=1.0e-3, length=1.0)
    out, _ = run_case("wave", str(tmp_path_factory.mktemp("sinusoid")), changes, figures=False,
                      source=wave.MODELS)
    return out, omega


def test_phase_speed_matches_the_discrete_relation(sinusoid):
    out, omega = sinusoid
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        measured, discrete, c0, frames = wave.measured_phase_speed(out, omega)
    assert frames >= 3
    assert measured == pytest.approx(discrete, rel=1e-3)          # measured 1.5e-4 in make validate
    # the time step's phase error matters at this tolerance: without Verlet's correction the
    # prediction is off by about 1 % (semi-discrete relation at kδ = 1, Δt = 1.8 µs)
    chain = wave.Chain(Run(out))
    semi_discrete = omega / chain.k_of_omega(omega, verlet=False)
    assert abs(measured / semi_discrete - 1.0) > 3e-3
    assert measured < c0                                            # dispersion slows it down


def test_pulse_error_falls_as_delta_shrinks(tmp_path_factory):
    errors = []
    for dx in (2.0e-3, 1.0e-3):
        changes, times = wave.pulse_changes(dx)
        out, _ = run_case("wave", str(tmp_path_factory.mktemp(f"pulse{dx * 1e3:g}")), changes, figures=False,
                          source=wave.MODELS)
        errors.append(wave.pulse_error(out, times))
    # measured 0.137 and 0.0336 (ratio 4.09: second order in δ)
    assert errors[1] < 0.05
    assert 3.0 < errors[0] / errors[1] < 5.5
