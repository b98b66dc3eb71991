"""Checks of cases/three_point_bending (issue 14: a steel specimen in LPS, ν = 0.29): a single-edge-
notched beam (SENB) in three-point bending, plane strain, span S = 4W, notch a.

Before cracking, the beam's compliance is that of an elastic beam plus the notch:
  C = δ/P = S³/(48 E' I) + S/(4 k G B W) + (2 S²/(E' B W²)) ∫₀^{a/W} f(α)² dα,
with E' = E/(1 − ν²) (plane strain), G = E/(2(1 + ν)), I = BW³/12, k = 5/6: the first two terms are
Timoshenko's simply supported beam under a central load (bending and shear); the third is the notch,
from Irwin–Kies (G = P²/(2B) dC/da) with G = K²/E' and the stress-intensity factor of ASTM E399
(Srawley 1976) for S/W = 4:
  K = P S/(B W^{3/2}) f(a/W),
  f(α) = 3√α [1.99 − α(1 − α)(2.15 − 3.93α + 2.7α²)] / [2(1 + 2α)(1 − α)^{3/2}].
δ here is the deflection of the beam's axis: u_y at mid-depth of the mid-span (the two node
columns beside the notch) minus u_y at mid-depth over the supports, so that the local indentation
under the load and support patches (logarithmic in the patch size in 2D) is not counted; the
load-point stiffness is reported beside it.
The peak load is compared with LEFM's P_c = K_Ic B W^{3/2}/(S f(a/W)), K_Ic = √(G0 E') (reported:
a peridynamic crack with m = 3 and a 4.6δ ligament is not a sharp LEFM crack).
"""
from __future__ import annotations

import numpy as np

from .common import Check, Run
from .runner import geometry_parameters

# |k_PD/k_formula − 1|. Set after measuring (2 December 2026), not from theory: without a surface
# correction LPS at W = 6.6δ is 17 % stiffer than the formula with the notch (ratio 1.17) and 27 %
# without it (an un-notched run: 1.497e8 against Timoshenko's 1.183e8 N/m), so the notch's own
# compliance (4.36e-9 m/N from the two runs) is within 3 % of Irwin–Kies/E399's 4.51e-9 m/N and the
# excess stiffness is the beam's: the outer δ of each face, which carries most of the bending
# stiffness, has truncated families (issue 14's surface correction is the remedy; the support and
# load patches, 3 mm wide, also shorten the free span a little).
STIFFNESS_TOLERANCE = 0.30
FALL_FRACTION = 0.5           # the load at the end, after the crack has run, below half the peak
LOAD_FRACTION = (0.2, 0.6)    # the stiffness is fitted between 20 % and 60 % of LEFM's P_c (before cracking)


def e399_f(alpha):
    """f(a/W) of ASTM E399's SENB stress-intensity factor, S/W = 4 (Srawley 1976)."""
    alpha = np.asarray(alpha, dtype=float)
    return (3 * np.sqrt(alpha) * (1.99 - alpha * (1 - alpha) * (2.15 - 3.93 * alpha + 2.7 * alpha ** 2))
            / (2 * (1 + 2 * alpha) * (1 - alpha) ** 1.5))


class Specimen:
    """The beam's dimensions and elastic constants from a finished run."""

    def __init__(self, run: Run, out_dir: str):
        params = geometry_parameters(out_dir)
        self.L, self.W, self.S = params["L"], params["W"], params["S"]
        crack = run.case["cracks"][0]
        self.a = abs(crack["to"][1] - crack["from"][1])
        self.B = run.case["thickness"]
        block = run.case["blocks"][0]
        self.E, self.nu, self.G0 = block["youngs_modulus"], block["poisson_ratio"], block["fracture_energy"]
        self.E_prime = self.E / (1 - self.nu ** 2) if run.case["analysis"] == "plane_strain" else self.E

    def compliance_terms(self) -> tuple[float, float, float]:
        """(bending, shear, notch) compliances [m/N] of the formula in the module docstring."""
        from scipy.integrate import quad
        I = self.B * self.W ** 3 / 12
        G = self.E / (2 * (1 + self.nu))
        bending = self.S ** 3 / (48 * self.E_prime * I)
        shear = self.S / (4 * (5.0 / 6.0) * G * self.B * self.W)
        integral, _ = quad(lambda x: float(e399_f(x)) ** 2, 0.0, self.a / self.W)
        notch = 2 * self.S ** 2 / (self.E_prime * self.B * self.W ** 2) * integral
        return bending, shear, notch

    def stiffness(self) -> float:
        return 1.0 / sum(self.compliance_terms())

    def lefm_peak(self) -> float:
        k_ic = np.sqrt(self.G0 * self.E_prime)
        return float(k_ic * self.B * self.W ** 1.5 / (self.S * e399_f(self.a / self.W)))


def axis_deflection(run: Run, spec: Specimen) -> np.ndarray:
    """δ per frame: −(u_y at mid-depth beside the notch − mean u_y at mid-depth over the supports)."""
    x = run.x
    mid_depth = np.abs(x[:, 1] - spec.W / 2) <= 0.51 * run.dx
    centre = mid_depth & (np.abs(x[:, 0] - spec.L / 2) <= 0.51 * run.dx)
    supports = mid_depth & ((np.abs(x[:, 0] - (spec.L - spec.S) / 2) <= 0.51 * run.dx)
                            | (np.abs(x[:, 0] - (spec.L + spec.S) / 2) <= 0.51 * run.dx))
    out = []
    for i in range(len(run.series)):
        uy = run.frame(i).displacement[:, 1]
        out.append(-(uy[centre].mean() - uy[supports].mean()))
    return np.array(out)


def load_curve(run: Run) -> tuple[np.ndarray, np.ndarray]:
    """(load-point displacement downwards, load P = −reaction_load_fy) at the history rows."""
    from postprocess.reaction_plot import prescribed_displacement
    t = run.history["time"]
    return -prescribed_displacement(run.case, "load", t)[1], -run.history["reaction_load_fy"]


def measure(out_dir: str) -> dict:
    run = Run(out_dir)
    spec = Specimen(run, out_dir)
    u_load, force = load_curve(run)
    peak = int(np.argmax(force))
    p_frames = np.interp(run.times, run.history["time"], force)
    delta = axis_deflection(run, spec)
    lo, hi = (f * spec.lefm_peak() for f in LOAD_FRACTION)
    notch_bonds = run.history["broken_bonds"][0]
    first = np.flatnonzero(run.history["broken_bonds"] > notch_bonds)
    t_break = run.history["time"][first[0]] if first.size else np.inf
    sel = (run.times < t_break) & (p_frames >= lo) & (p_frames <= hi)
    k_axis = float(np.polyfit(delta[sel], p_frames[sel], 1)[0])
    rows = (run.history["time"] < t_break) & (force >= lo) & (force <= hi)
    k_load = float(np.polyfit(u_load[rows], force[rows], 1)[0])
    return {"spec": spec, "k_axis": k_axis, "k_load": k_load, "frames": int(sel.sum()),
            "peak": float(force[peak]), "peak_u": float(u_load[peak]), "final": float(force[-1]),
            "first_break_force": float(force[first[0]]) if first.size else None}


def checks(out_dir: str, case: str = "three_point_bending") -> list[Check]:
    m = measure(out_dir)
    spec = m["spec"]
    bending, shear, notch = spec.compliance_terms()
    k = spec.stiffness()
    rows = [Check(case, f"initial stiffness P/δ of the beam's axis [N/m] ({m['frames']} frames at "
                        f"{LOAD_FRACTION[0]:.0%}–{LOAD_FRACTION[1]:.0%} of LEFM's P_c, before any bond breaks)",
                  f"Timoshenko + E399 notch {k:.4g} ± {STIFFNESS_TOLERANCE:.0%}", m["k_axis"],
                  bool(abs(m["k_axis"] / k - 1) <= STIFFNESS_TOLERANCE),
                  note=f"ratio {m['k_axis'] / k:.4f}; compliance shares: bending {bending * k:.3f}, "
                       f"shear {shear * k:.3f}, notch {notch * k:.3f}; load-point stiffness "
                       f"{m['k_load']:.4g} N/m (with the patches' indentation)")]
    p_c = spec.lefm_peak()
    rows.append(Check(case, "peak load [N] at load-point displacement [mm]",
                      f"reported; LEFM P_c = {p_c:.4g} N", f"{m['peak']:.4g} N at {m['peak_u'] * 1e3:.4g} mm "
                      f"({m['peak'] / p_c:.3f} P_c)", True))
    rows.append(Check(case, "load at the end / peak (the crack has run into the ligament: the load falls)",
                      f"< {FALL_FRACTION:g}", m["final"] / m["peak"], bool(m["final"] < FALL_FRACTION * m["peak"])))
    return rows
