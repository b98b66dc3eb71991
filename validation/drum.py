"""Checks of cases/drum: a square membrane pre-tensioned by a uniform strain ε0 and struck, without
damping. Its fundamental frequency must match the membrane's f = (√2/(2L))·√(T/(ρh)),
T = E·ε0·h/(1 − ν) with plane-stress PMB's ν = 1/3; its energy KE + U must not drift (docs/theory.md
C4 without breakage); the clamping frame must hold the pre-strained edge where it was put.

The out-of-plane restoring force is geometric: each pre-stretched bond pulls along its current
direction, so a deflection w gives it a z-component c·ε0·V·(w_j − w_i)/|y_ij|, a nonlocal Laplacian
whose continuum limit is exactly T∇²w/h (its lattice sum differs from the integral by the factor
of docs/theory.md C1, 1.025 at δ = 3.015 dx, and the nonlocal clamp moves the edge by ~dx).
The frequency is measured on the modal coordinate q(t) = Σ w_i φ_i / Σ φ_i², φ = sin(πx/L)·sin(πy/L)
over the free span: the projection removes the other (odd, odd) modes the uniform blow excites."""
from __future__ import annotations

import numpy as np

from .common import Check, Run
from .runner import geometry_parameters

NU_PLANE_STRESS = 1.0 / 3.0
TOLERANCE = 0.03           # |f_PD / f − 1| (the 3 %)
DRIFT_MAX = 1.0e-3         # |KE + U − W_ext − E(0)| / KE(0) over the run, no damping


def geometry(run: Run) -> tuple[float, float]:
    """(L, w): the free span and the clamping frame's width, from the case's gmsh parameters."""
    p = geometry_parameters(run.out_dir)
    return float(p.get("L", 0.05)), float(p.get("w", 1.5e-3))


def pre_strain(run: Run) -> float:
    """ε0: the x gradient of the initial displacement condition (case.json)."""
    for ic in run.case["initial_conditions"]:
        if ic["kind"] == "displacement" and ic["component"] == 0 and ic.get("gradient"):
            return float(ic["gradient"])
    raise ValueError(f"{run.out_dir}: no pre-strain (initial displacement with a gradient) in case.json")


def theory_frequency(run: Run) -> float:
    """f = (√2/(2L))·√(σ0/ρ), σ0 = T/h = E·ε0/(1 − ν): the (1,1) mode of a square membrane."""
    block = run.case["blocks"][0]
    length, _ = geometry(run)
    sigma0 = block["youngs_modulus"] * pre_strain(run) / (1.0 - NU_PLANE_STRESS)
    return float(np.sqrt(2.0) / (2.0 * length) * np.sqrt(sigma0 / block["density"]))


def modal_coordinate(run: Run) -> tuple[np.ndarray, np.ndarray]:
    """(times, q): the projection of w on the fundamental mode shape over the free span."""
    length, w = geometry(run)
    xi, eta = (run.x[:, 0] - w) / length, (run.x[:, 1] - w) / length
    inside = (xi > 0) & (xi < 1) & (eta > 0) & (eta < 1)
    phi = np.where(inside, np.sin(np.pi * xi) * np.sin(np.pi * eta), 0.0)
    q = np.array([np.sum(run.frame(i).displacement[:, 2] * phi) for i in range(len(run.series))])
    return run.times, q / np.sum(phi * phi)


def zero_crossing_frequency(t: np.ndarray, q: np.ndarray) -> tuple[float, int]:
    """(1 / (2 × mean spacing of the zero crossings), number of crossings); crossings by linear
    interpolation between frames (q starts at 0 and rises: the first crossing is t = 0)."""
    k = np.where(np.sign(q[1:]) != np.sign(q[:-1]))[0]
    k = k[q[k] != 0.0] if len(k) > 2 else k
    crossings = t[k] - q[k] * (t[k + 1] - t[k]) / (q[k + 1] - q[k])
    crossings = np.concatenate([[0.0], crossings[crossings > 0.0]])
    if len(crossings) < 3:
        return float("nan"), len(crossings)
    return float(1.0 / (2.0 * np.mean(np.diff(crossings)))), len(crossings)


def fitted_frequency(t: np.ndarray, q: np.ndarray, guess: float) -> float:
    """Least-squares fit of a·sin(2πft) + b·cos(2πft) to q(t)."""
    from scipy.optimize import curve_fit

    def model(tt, a, b, f):
        return a * np.sin(2 * np.pi * f * tt) + b * np.cos(2 * np.pi * f * tt)

    (a, _b, f), _ = curve_fit(model, t, q, p0=[np.max(np.abs(q)), 0.0, guess])
    return float(f)


def energy_drift(run: Run) -> tuple[float, float]:
    """(max |E(t) − E(0)| / KE(0), KE(0)) with E = KE + U − W_ext − damping work."""
    h = run.history
    energy = h["kinetic_energy"] + h["strain_energy"] - h["external_work"] + h["damping_work"]
    ke0 = float(h["kinetic_energy"][0])
    return float(np.max(np.abs(energy - energy[0])) / ke0), ke0


def clamp_motion(run: Run) -> float:
    """The largest change of any clamped node's displacement over the run, / (ε0·L)."""
    clamped = run.node_set("clamped")
    first, last = run.frame(0).displacement[clamped], run.frame(-1).displacement[clamped]
    length, _ = geometry(run)
    return float(np.max(np.abs(last - first)) / (pre_strain(run) * length))


def checks(out_dir: str, case: str = "drum") -> list[Check]:
    run = Run(out_dir)
    f_theory = theory_frequency(run)
    t, q = modal_coordinate(run)
    f_zero, crossings = zero_crossing_frequency(t, q)
    f_fit = fitted_frequency(t, q, f_zero if np.isfinite(f_zero) else f_theory)
    rows = []
    length, _ = geometry(run)
    rows.append(Check(case, f"fundamental frequency, zero crossings of the modal coordinate [Hz] "
                            f"({crossings} crossings, L/dx = {length / run.dx:.0f})",
                      f"{f_theory:.1f} ± {TOLERANCE:.0%}", f_zero,
                      bool(abs(f_zero / f_theory - 1.0) <= TOLERANCE),
                      note=f"f_PD/f = {f_zero / f_theory:.4f} (zero crossings), "
                           f"{f_fit / f_theory:.4f} (sinusoid fit, {f_fit:.1f} Hz)"))
    rows.append(Check(case, "fundamental frequency, sinusoid fit [Hz]", f"{f_theory:.1f} ± {TOLERANCE:.0%}",
                      f_fit, bool(abs(f_fit / f_theory - 1.0) <= TOLERANCE)))
    drift, ke0 = energy_drift(run)
    rows.append(Check(case, f"energy drift max abs(KE + U − W_ext − E(0)) / KE(0), no damping (KE(0) = {ke0:.3g} J)",
                      f"≤ {DRIFT_MAX:g}", drift, drift <= DRIFT_MAX))
    moved = clamp_motion(run)
    rows.append(Check(case, "clamped frame: largest displacement change / (ε0·L)", "≤ 1e-12", moved,
                      moved <= 1e-12))
    return rows


# ---- convergence in dx and the energy error's order in Δt (make validate: "drum_convergence")
CONVERGENCE_DX = (2.0e-3, 1.0e-3)      # the case itself (out/drum) adds dx = 0.5 mm


def coarse_changes(dx: float, end: float = 4.7e-3, safety: float | None = None) -> dict:
    """The case at spacing dx: the frame (and its layer) 3 dx wide, so the free span stays L."""
    changes = {"geometry": {"parameters": {"w": 3 * dx}}, "discretization": {"dx": dx},
               "node_sets": {"clamped": {"layer": 3 * dx}}, "time": {"end": end},
               "figures": {"times": [0.0, end]}}
    if safety is not None:
        changes["time"]["safety_factor"] = safety
        changes["output"] = {"history_every": 1}
    return changes


def frequency_ratio(out_dir: str) -> tuple[float, float]:
    """(dx/L, f_PD/f from the zero crossings)."""
    run = Run(out_dir)
    t, q = modal_coordinate(run)
    length, _ = geometry(run)
    return run.dx / length, zero_crossing_frequency(t, q)[0] / theory_frequency(run)


def validate_convergence(report_dir: str, case: str = "drum") -> list[Check]:
    import os
    from .runner import ROOT, run_case
    work = os.path.join(report_dir, "work", "drum")
    points = []
    for dx in CONVERGENCE_DX:
        out, _ = run_case("drum", os.path.join(work, f"dx{dx * 1e3:g}mm"), coarse_changes(dx), figures=False)
        points.append(frequency_ratio(out))
    full = os.path.join(ROOT, "out", "drum")
    if os.path.exists(os.path.join(full, "history.csv")):
        points.append(frequency_ratio(full))
    points.sort(reverse=True)
    errors = [abs(r - 1.0) for _, r in points]
    rows = [Check(case, "abs(f_PD/f − 1) at L/dx = " + ", ".join(f"{1 / h:.0f}" for h, _ in points),
                  "falls as dx shrinks", ", ".join(f"{e:.3g}" for e in errors),
                  bool(all(errors[i + 1] < errors[i] for i in range(len(errors) - 1))),
                  note="f_PD/f = " + ", ".join(f"{r:.4f}" for _, r in points))]
    drift = []
    for safety in (0.8, 0.4):
        out, _ = run_case("drum", os.path.join(work, f"dt{safety:g}"), coarse_changes(2.0e-3, 2.4e-3, safety),
                          figures=False)
        drift.append(energy_drift(Run(out))[0])
    ratio = drift[0] / drift[1]
    rows.append(Check(case, f"energy error / KE(0) at safety factor 0.8 and 0.4 (dx = 2 mm, no damping): "
                            f"{drift[0]:.3g}, {drift[1]:.3g}; their ratio",
                      "4 ± 0.5 (C4: velocity Verlet, O(Δt²))", ratio, bool(3.5 <= ratio <= 4.5)))
    validate_convergence.result = points
    return rows
