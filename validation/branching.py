"""Checks of cases/branching (docs/theory.md C7, Bobaru & Zhang 2015): the crack-tip speed stays
below the Rayleigh speed, the crack branches before the right edge, and the branches are
symmetric about the notch line; also the energy balance with broken bonds (docs/theory.md C4)."""
from __future__ import annotations

import numpy as np

from postprocess import crack_tip

from .common import Check, Run

RAYLEIGH = 3058.0          # m/s, plane stress ν = 1/3, E = 72 GPa, ρ = 2440 (docs/theory.md C7 [D]); rayleigh_speed()
DAMAGED = crack_tip.DAMAGED  # damage above which a node belongs to the crack (the normal output's too)
SPEED_WINDOW = 2.0e-6      # s: tip speed over windows this long (a lattice crack advances in jumps)
SYMMETRY_MIN = 0.95        # share of crack nodes whose mirror image is a crack node too
BALANCE_MAX = 0.02         # |KE + U + broken-bond energy − W_ext| / W_ext at the end


def rayleigh_speed(run: Run) -> float:
    """c_R of the run's (first) block: the root of the Rayleigh equation
    (2 − ξ²)² = 4√(1 − ξ²η²)√(1 − ξ²), ξ = c/c_S, η = c_S/c_L, with the in-plane wave speeds of the
    analysis: c_L² = (κ + μ)/ρ (κ the in-plane bulk modulus: E/(2(1 − ν)) in plane stress, λ + μ in
    plane strain), c_S² = μ/ρ. ν is the block's poisson_ratio (LPS), else PMB's fixed 1/3 (plane
    stress) or 1/4. For C7's glass with PMB (ν = 1/3, plane stress) it gives 3058 m/s (RAYLEIGH)."""
    from scipy.optimize import brentq
    block = run.case["blocks"][0]
    plane_stress = run.case.get("analysis") == "plane_stress"
    nu = block.get("poisson_ratio", 1.0 / 3.0 if plane_stress else 0.25)
    e, rho = block["youngs_modulus"], block["density"]
    mu = e / (2 * (1 + nu))
    kappa = e / (2 * (1 - nu)) if plane_stress else e / (2 * (1 + nu) * (1 - 2 * nu))
    c_s, c_l = np.sqrt(mu / rho), np.sqrt((kappa + mu) / rho)
    eta = c_s / c_l
    f = lambda x: (2 - x * x) ** 2 - 4 * np.sqrt(1 - x * x * eta * eta) * np.sqrt(1 - x * x)
    return float(brentq(f, 0.5, 0.999999) * c_s)


def notch_line(run: Run) -> float:
    """y of the notch (the pre-crack of case.json)."""
    return float(run.case["cracks"][0]["from"][1])


def notch_tip(run: Run) -> np.ndarray:
    c = run.case["cracks"][0]
    return np.array(max((c["from"], c["to"]), key=lambda p: p[0])[:2], dtype=float)


def tip_track(run: Run) -> crack_tip.Track:
    """The upper branch's tip (y ≥ notch line; the lower half mirrors it), running along +x from
    the notch tip: the shared tracker of the normal output (postprocess/crack_tip.py)."""
    return crack_tip.Track("upper", np.array([*notch_tip(run), 0.0]), np.array([1.0, 0.0, 0.0]),
                           side=np.array([0.0, 1.0, 0.0]))


def tip_history(run: Run) -> tuple[np.ndarray, np.ndarray]:
    """(times, tip positions (x, y)): in each frame the crack node of the upper half farthest along
    x beyond the notch tip, else the notch tip."""
    masks = [run.frame(i).damage > DAMAGED for i in range(len(run.series))]
    return run.times, crack_tip.tip_positions(run.x, masks, tip_track(run))[:, :2]


def tip_speeds(run: Run) -> tuple[np.ndarray, np.ndarray]:
    """(window mid-times, speeds): |Δ tip| / Δt over SPEED_WINDOW."""
    t, tips = tip_history(run)
    lag = max(1, int(round(SPEED_WINDOW / np.median(np.diff(t)))))
    return crack_tip.tip_speeds(t, tips, lag)


def branch_point(run: Run, index: int = -1) -> float | None:
    """The smallest x beyond the notch tip at which the crack nodes of a node column form two
    groups, one above and one below the notch line, separated by more than 2δ (None if never)."""
    yc, tip0 = notch_line(run), notch_tip(run)
    crack = (run.frame(index).damage > DAMAGED) & (run.x[:, 0] > tip0[0])
    columns = np.round(run.x[crack, 0] / run.dx).astype(np.int64)
    ys = run.x[crack, 1]
    split = [c for c in np.unique(columns)
             if (ys[columns == c] > yc + run.horizon).any() and (ys[columns == c] < yc - run.horizon).any()
             and not (np.abs(ys[columns == c] - yc) <= run.horizon).any()]
    return float(min(split) * run.dx) if split else None


def mirror_agreement(run: Run, index: int = -1) -> float:
    """Share of the crack nodes beyond the notch whose mirror image in the notch line lies within
    δ of a crack node (the crack path is resolved to about δ, so "symmetric" means to within δ)."""
    from scipy.spatial import cKDTree
    yc, tip0 = notch_line(run), notch_tip(run)
    crack = run.x[(run.frame(index).damage > DAMAGED) & (run.x[:, 0] > tip0[0]), :2]
    if len(crack) == 0:
        return 0.0
    mirrored = crack * np.array([1.0, -1.0]) + np.array([0.0, 2.0 * yc])
    distance, _ = cKDTree(crack).query(mirrored)
    return float(np.mean(distance <= run.horizon * (1.0 + 1e-9)))


def energy_balance(run: Run) -> tuple[float, float]:
    """(|KE + U + contact + indenter + broken-bond energy + damping work − W_ext| at the end / W_ext
    at the end, W_ext). Every history.csv has these columns since issue 16 (0 for a term the case lacks)."""
    h = run.history
    total = (h["kinetic_energy"] + h["strain_energy"] + h["contact_energy"] + h["indenter_energy"]
             + h["broken_bond_energy"] + h["damping_work"])
    work = h["external_work"]
    return float(abs(total[-1] - work[-1]) / abs(work[-1])), float(work[-1])


def checks(out_dir: str, case: str = "branching") -> list[Check]:
    run = Run(out_dir)
    rows = []
    t_mid, speed = tip_speeds(run)
    k = int(np.argmax(speed))
    c_r = rayleigh_speed(run)
    rows.append(Check(case, f"max crack-tip speed over {SPEED_WINDOW * 1e6:g} µs [m/s] (at {t_mid[k] * 1e6:.3g} µs)",
                      f"< c_R = {c_r:.0f}", float(speed[k]), bool(speed[k] < c_r)))
    x_branch = branch_point(run)
    length = float(run.x[:, 0].max() + run.dx / 2)
    rows.append(Check(case, "branching point x [mm]", f"branches before the right edge ({length * 1e3:.4g})",
                      x_branch * 1e3 if x_branch is not None else "no branching",
                      x_branch is not None and x_branch < length))
    share = mirror_agreement(run)
    rows.append(Check(case, "crack nodes whose mirror image is within δ of the crack", f"≥ {SYMMETRY_MIN:g}", share,
                      share >= SYMMETRY_MIN))
    balance, work = energy_balance(run)
    rows.append(Check(case, f"energy balance abs(KE + U + E_broken − W_ext) / W_ext (W_ext = {work:.3g} J)",
                      f"≤ {BALANCE_MAX:g}", balance, balance <= BALANCE_MAX))
    return rows
