"""Wave speed of the linear peridynamic solid (LPS, issue 14) on the 1D chain of
validation/wave.py (one row of a plane-stress lattice, m = 3, ν = 0.3), the PMB check's model:

1. Driven sinusoids, a shorter wave (kδ = 1) and a long one (kδ = 0.5): the phase speed ω/k of the
   steady train against the discrete LPS dispersion relation of the chain
   (wave.chain_omega_squared: the Fourier symbol of LPS's linearised energy, Silling et al. 2007,
   Mitchell's form) with velocity Verlet's phase sin(ωΔt/2) = ω_s(k)Δt/2, within 0.1 %.
Energy without breaking is not re-measured here: solver/tests/materials/test_lps.cpp
(VerletFreeVibrationConservesEnergyToSecondOrder, a free vibrating plate, ν = 0.3) checks that KE + U
does not drift and that its oscillation falls 4.3× when Δt halves (docs/theory.md C4). On this chain a
travelling pulse is a poor C4 probe: KE and U barely exchange, and the spread of KE + U fell 19× (not
4×) from safety factor 0.8 to 0.4 (2.9·10⁻⁸ → 1.6·10⁻⁹ of KE + U).
"""
from __future__ import annotations

import os
import warnings


from . import wave
from .common import Check, Run
from .runner import run_case

LPS = {"model": "lps", "poisson_ratio": 0.3}
# (kδ, bar length [m]): the window of wave.measured_phase_speed needs ≥ 20 wavelengths before the
# ramp's tail, so the long wave needs the longer bar.
SINUSOIDS = ((1.0, 1.5), (0.5, 2.5))


def run_all(work: str, sinusoids=SINUSOIDS) -> dict:
    result = {"sinusoids": []}
    for k_delta, length in sinusoids:
        changes, omega = wave.sinusoid_changes(dx=wave.SINUSOID_DX, length=length, k_delta=k_delta, material=LPS)
        out, _ = run_case("wave", os.path.join(work, f"sinusoid_kd{k_delta:g}"), changes, figures=False,
                          source=wave.MODELS)
        with warnings.catch_warnings():   # curve_fit's covariance
            warnings.simplefilter("ignore")
            measured, discrete, c0, frames = wave.measured_phase_speed(out, omega)
        chain = wave.Chain(Run(out))
        result["sinusoids"].append({"k_delta": k_delta, "out": out, "omega": omega, "measured": measured,
                                    "discrete": discrete, "c0": c0, "frames": frames,
                                    "semi_discrete": omega / chain.k_of_omega(omega, verlet=False)})
    return result


def checks_from(result: dict, case: str = "wave_lps") -> list[Check]:
    rows = []
    for s in result["sinusoids"]:
        rel = s["measured"] / s["discrete"] - 1.0
        rows.append(Check(case, f"LPS (ν = 0.3) chain: phase speed ω/k of a driven sinusoid, kδ = {s['k_delta']:g}, "
                                f"m = 3 [m/s] ({s['frames']} frames)",
                          f"discrete LPS relation with Verlet phase {s['discrete']:.4f} ± 0.1 %", s["measured"],
                          bool(abs(rel) <= wave.PHASE_TOLERANCE),
                          note=f"relative error {rel:+.2e}; without Verlet's phase {s['semi_discrete']:.4f}; "
                               f"v/c0 = {s['measured'] / s['c0']:.4f} (c0 = √(4κ/ρ) = {s['c0']:.2f} m/s)"))
    return rows


def validate(report_dir: str) -> list[Check]:
    result = run_all(os.path.join(report_dir, "work", "wave_lps"))
    validate.result = result
    return checks_from(result)
