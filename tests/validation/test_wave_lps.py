"""Fast LPS wave check (validation/wave_lps.py): on the 1D chain (one row of a plane-stress lattice,
ν = 0.3, m = 3), a driven sinusoid at kδ = 1 travels at the phase speed of the discrete LPS
dispersion relation (wave.chain_omega_squared) with Verlet's phase, to 0.1 % (a 1 m bar instead of
make validate's 1.5 m)."""
import warnings

import numpy as np
import pytest

from validation import wave, wave_lps
from validation.common import Run
from validation.runner import run_case


def test_lps_phase_speed_matches_the_discrete_lps_relation(tmp_path):
    changes, omega = wave.sinusoid_changes(dx=1.0e-3, length=1.0, k_delta=1.0, material=wave_lps.LPS)
    out, _ = run_case("wave", str(tmp_path), changes, figures=False, source=wave.MODELS)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        measured, discrete, c0, frames = wave.measured_phase_speed(out, omega)
    assert frames >= 3
    assert measured == pytest.approx(discrete, rel=1e-3)   # measured +1.1e-4 in make validate (1.5 m bar)
    chain = wave.Chain(Run(out))
    assert chain.model == "lps"
    # the relation is LPS's, not PMB's: PMB's chain of the same E runs at about 770 m/s here,
    # and the LPS chain's long-wave speed is √(4κ/ρ), κ = E/(2(1 − ν)), not √(E/ρ)
    assert c0 == pytest.approx(np.sqrt(4 * 1.0e9 / (2 * 0.7) / 1000.0), rel=1e-12)
    pmb = np.sqrt(wave.chain_omega_squared(1.0 / chain.delta, model="pmb", E=chain.E, rho=chain.rho, h=chain.h,
                                           dx=chain.dx, delta=chain.delta)) * chain.delta
    assert abs(measured / pmb - 1.0) > 0.5
    # Verlet's phase matters at this tolerance (0.54 % at this Δt in make validate's run)
    assert abs(measured / (omega / chain.k_of_omega(omega, verlet=False)) - 1.0) > 2e-3
    assert measured < c0
