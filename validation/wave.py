"""Wave speed in the 1D chain of docs/theory.md C2, run as one row of lattice nodes (validation/models/
wave.yaml: bar.geo with H = dx, so every bond lies along x; a chain node has the 2D plane-stress
micromodulus c and volume V = dx²h).

1. A sinusoid: the left end is driven at angular frequency ω (amplitude ramped up over a few
   periods); the wave number k of the steady wave train, fitted over tens of wavelengths before the
   front, must give the phase speed ω/k of the discrete dispersion relation (lattice sum)
   ρω_s(k)² = Σ_{j≤m} 2cV(1 − cos kjΔx)/(jΔx), with velocity Verlet's sin(ωΔt/2) = ω_s(k)Δt/2,
   within 0.1 %. The solver has no periodic boundary: a long bar is measured before the front.
2. A smooth (Gaussian) pulse: the shape at time t2 against d'Alembert's transport of the shape at t1
   at the long-wave speed c0 (c0² = Σ_j cV·jΔx/ρ, the k → 0 limit of the same sum); at fixed
   m = δ/Δx the error falls as δ shrinks (C2: O(δ²)).
"""
from __future__ import annotations

import os

import numpy as np
import yaml

from .common import Check, Run
from .runner import ROOT, run_case

MODELS = os.path.join(ROOT, "validation", "models")
PHASE_TOLERANCE = 1.0e-3
K_DELTA = 1.0              # the sinusoid's kδ (C2 table: continuum v/c0 = 0.9794 there)
RAMP_PERIODS = 4


def base_model() -> dict:
    with open(os.path.join(MODELS, "wave.yaml"), encoding="utf-8") as stream:
        return yaml.safe_load(stream)


def chain_omega_squared(k: float, *, model: str, E: float, rho: float, h: float, dx: float, delta: float,
                        nu: float | None = None) -> float:
    """ω_s(k)² of the semi-discrete chain (one row of a plane-stress lattice, bonds j = 1..M = ⌊δ/Δx⌋
    on each side, V = Δx²h, ω = 1, full volumes), exact in space and continuous in time.

    pmb (docs/theory.md C2): ρω² = Σ_{j≤M} 2cV(1 − cos kjΔx)/(jΔx), c = 9E/(πhδ³).

    lps: the linearised LPS (materials/lps/lps.hpp) on the chain. With e_j = n_j·(u_j − u_i) and
    W_i = (κ/2)θ_i² + (α/(2m)) Σ_j ω(e_j − θ_i|ξ_j|/d)²V (Silling et al. 2007, eq. 92; Mitchell's
    ordinary state-based form), expanding the square with θ_i = (d/m) Σ_j ω|ξ_j| e_j V gives
    W_i = (κ/2 − α/(2d²))θ_i² + (α/(2m)) Σ_j ω e_j² V. A plane wave u_i = U e^{ik·x_i} has
    θ = i(d/m) S·U, S = Σ_j ω|ξ_j| V n_j sin(k·ξ_j), and |e_j|² = 2(1 − cos k·ξ_j)(n_j·U)², so the
    dynamical matrix (ρω²U = D U, D the Fourier symbol of the energy's Hessian per volume) is
        D(k) = (κ − α/d²)(d/m)² S Sᵀ + (α/m) Σ_j ω V 2(1 − cos k·ξ_j) n_j n_jᵀ.
    On the chain (n = ±x, both sides of the node): m = 2Σ_{j≤M} (jΔx)²V, S = 2Σ (jΔx)V sin(kjΔx),
    D = (κ − α/4)(2S/m)² + (α/m)·2Σ 2V(1 − cos kjΔx), with plane stress's κ = E/(2(1 − ν)),
    α = 8μ, d = 2. Its long-wave limit is ρc0² = 4κ (not E: the chain's family is one line, while
    m, d and α are the plane's); in a bulk 2D lattice the same D gives the continuum κ + μ
    (longitudinal) and μ (transverse)."""
    r = np.arange(1, int(np.floor(delta / dx + 1e-9)) + 1) * dx
    V = dx * dx * h
    if model != "lps":
        c = 9.0 * E / (np.pi * h * delta ** 3)      # plane stress, docs/theory.md T2
        return float(np.sum(2 * c * V * (1 - np.cos(k * r)) / r) / rho)
    kappa, alpha, d = E / (2 * (1 - nu)), 8.0 * E / (2 * (1 + nu)), 2.0
    m = 2 * np.sum(r * r * V)
    S = 2 * np.sum(r * V * np.sin(k * r))
    D = (kappa - alpha / d ** 2) * (d * S / m) ** 2 + alpha / m * 2 * np.sum(2 * V * (1 - np.cos(k * r)))
    return float(D / rho)


class Chain:
    """The chain's lattice sums from a finished run (case.json): the material, V, Δx, partners j ≤ δ/Δx."""

    def __init__(self, run: Run):
        block = run.case["blocks"][0]
        self.rho, self.E = block["density"], block["youngs_modulus"]
        self.model, self.nu = block.get("model", "pmb"), block.get("poisson_ratio")
        self.h, self.dx, self.delta = run.case["thickness"], run.dx, run.horizon
        self.c = 9.0 * self.E / (np.pi * self.h * self.delta ** 3)      # plane stress, docs/theory.md T2
        self.V = self.dx ** 2 * self.h
        self.j = np.arange(1, int(np.floor(self.delta / self.dx + 1e-9)) + 1)
        self.dt = float(np.median(np.diff(run.history["time"])[1:] / np.diff(run.history["step"])[1:]))

    def omega_space(self, k: float) -> float:
        """ω_s(k) of the semi-discrete chain (exact in space, continuous in time)."""
        # max(·, 0): at k → 0 LPS's two O(k²) terms cancel to round-off, which can dip below zero
        return float(np.sqrt(max(0.0, chain_omega_squared(k, model=self.model, E=self.E, rho=self.rho, h=self.h,
                                                          dx=self.dx, delta=self.delta, nu=self.nu))))

    def c0(self) -> float:
        """The long-wave speed lim_{k→0} ω_s(k)/k: Σ_j cV·jΔx/ρ (pmb), 4κ/ρ (lps, chain_omega_squared)."""
        if self.model == "lps":
            return float(np.sqrt(4 * self.E / (2 * (1 - self.nu)) / self.rho))
        return float(np.sqrt(np.sum(self.c * self.V * self.j * self.dx) / self.rho))

    def k_of_omega(self, omega: float, verlet: bool = True) -> float:
        """The wave number a drive at ω excites: ω_s(k) = (2/Δt)·sin(ωΔt/2) with Verlet, else ω."""
        from scipy.optimize import brentq
        target = 2.0 / self.dt * np.sin(omega * self.dt / 2.0) if verlet else omega
        return float(brentq(lambda k: self.omega_space(k) - target, 1e-9, np.pi / self.dx))


def drive_table(omega: float, amplitude: float, end: float) -> list[list[float]]:
    """u(t) = A·ramp(t)·sin(ωt), ramp = (1 − cos(πt/T_r))/2 over RAMP_PERIODS, 64 samples a period."""
    period = 2 * np.pi / omega
    t = np.arange(0.0, end + period / 64, period / 64)
    ramp = np.where(t < RAMP_PERIODS * period, 0.5 * (1 - np.cos(np.pi * t / (RAMP_PERIODS * period))), 1.0)
    return [[float(a), float(b)] for a, b in zip(t, amplitude * ramp * np.sin(omega * t))]


def sinusoid_changes(dx: float = 1.0e-3, length: float = 1.5, k_delta: float = K_DELTA,
                     material: dict | None = None) -> tuple[dict, float]:
    """(case changes, ω) for the driven sinusoid at kδ = k_delta (ω from the semi-discrete relation);
    material: changes to the chain's material (e.g. {model: lps, poisson_ratio: 0.3})."""
    m = base_model()
    bar = dict(m["materials"]["bar"], **(material or {}))
    delta = m["discretization"]["horizon_factor"] * dx
    E, rho, h = float(bar["youngs_modulus"]), float(bar["density"]), float(m["thickness"])
    sums = dict(model=bar.get("model", "pmb"), E=E, rho=rho, h=h, dx=dx, delta=delta, nu=bar.get("poisson_ratio"))
    k = k_delta / delta
    omega = float(np.sqrt(chain_omega_squared(k, **sums)))
    c0 = float(np.sqrt(chain_omega_squared(1e-3 / delta, **sums)) / (1e-3 / delta))   # ≈ Chain.c0 (1e-7)
    end = 0.95 * length / c0          # the front (group speed < c0) stays inside the bar
    changes = {"geometry": {"parameters": {"Lx": length, "H": dx, "lc": max(dx, length / 2000)}},
               "discretization": {"dx": dx},
               "boundary_conditions": [{"set": "left", "displacement": {"x": drive_table(omega, 1e-6, end)}}],
               "time": {"end": end}, "output": {"every_steps": None, "every_time": end / 40}}
    if material:
        changes["materials"] = {"bar": material}
    return changes, omega


def fitted_wavenumber(x: np.ndarray, u: np.ndarray, guess: float) -> float:
    from scipy.optimize import curve_fit

    def model(xx, a, b, k):
        return a * np.sin(k * xx) + b * np.cos(k * xx)

    a0 = np.max(np.abs(u))
    best = None
    import warnings
    for phase in (0.0, np.pi / 2):
        try:
            with warnings.catch_warnings():   # the covariance is not used
                warnings.simplefilter("ignore")
                p, _ = curve_fit(model, x, u, p0=[a0 * np.cos(phase), a0 * np.sin(phase), guess])
        except RuntimeError:
            continue
        res = np.sum((model(x, *p) - u) ** 2)
        if best is None or res < best[0]:
            best = (res, p[2])
    return float(best[1])


def measured_phase_speed(out_dir: str, omega: float) -> tuple[float, float, float, int]:
    """(measured ω/k, discrete-relation ω/k, the chain's long-wave speed c0, frames used): k fitted
    over the steady part of the train, [10 wavelengths, the ramp's tail − 5 wavelengths], in each of
    the last six frames where that window spans at least 20 wavelengths; the mean k."""
    run = Run(out_dir)
    chain = Chain(run)
    k_expected = chain.k_of_omega(omega)
    wavelength = 2 * np.pi / k_expected
    order = np.argsort(run.x[:, 0])
    x = run.x[order, 0]
    ks = []
    for i in range(len(run.series) - 6, len(run.series)):
        t = run.times[i]
        tail = 0.9 * chain.c0() * (t - RAMP_PERIODS * 2 * np.pi / omega)   # the ramp's end has passed here
        window = (x > 10 * wavelength) & (x < tail - 5 * wavelength)
        if window.sum() < 20 * wavelength / chain.dx:
            continue
        u = run.frame(i).displacement[order, 0]
        ks.append(fitted_wavenumber(x[window], u[window], k_expected))
    return float(omega / np.mean(ks)), float(omega / k_expected), chain.c0(), len(ks)


# ---- the pulse
PULSE_WIDTH = 0.02          # m: the Gaussian's c0·τ
PULSE_TRAVEL = 0.4          # m between the two compared shapes


def pulse_changes(dx: float, horizon_factor: float | None = None,
                  material: dict | None = None) -> tuple[dict, tuple[float, float]]:
    """(case changes, (t1, t2)): the left end's layer δ driven by a Gaussian pulse of width
    PULSE_WIDTH; its centre passes x = 0.1 m at t1 and x = 0.1 m + PULSE_TRAVEL at t2.
    material: changes to the chain's material (as sinusoid_changes)."""
    m = base_model()
    factor = horizon_factor or m["discretization"]["horizon_factor"]
    delta = factor * dx
    E, rho, h = (float(v) for v in (m["materials"]["bar"]["youngs_modulus"], m["materials"]["bar"]["density"],
                                    m["thickness"]))
    c, V = 9.0 * E / (np.pi * h * delta ** 3), dx * dx * h
    r = np.arange(1, int(np.floor(delta / dx + 1e-9)) + 1) * dx
    c0 = float(np.sqrt(np.sum(c * V * r) / rho))
    if material and material.get("model") == "lps":      # Chain.c0 of LPS: 4κ/ρ
        c0 = float(np.sqrt(4 * E / (2 * (1 - material["poisson_ratio"])) / rho))
    tau = PULSE_WIDTH / c0
    t0 = 4 * tau
    length = 0.1 + PULSE_TRAVEL + 8 * PULSE_WIDTH + 0.05
    t1 = t0 + 0.1 / c0                     # centre at 0.1 m
    t2 = t1 + PULSE_TRAVEL / c0
    t = np.linspace(0.0, 2 * t0, 161)
    table = [[float(a), float(1e-6 * np.exp(-((a - t0) / tau) ** 2))] for a in t]
    table[-1][1] = 0.0
    changes = {"geometry": {"parameters": {"Lx": length, "H": dx, "lc": max(dx, length / 2000)}},
               "discretization": {"dx": dx, "horizon_factor": factor},
               "node_sets": {"left": {"layer": delta}},
               "boundary_conditions": [{"set": "left", "displacement": {"x": table}}],
               "time": {"end": t2}, "output": {"every_time": t2 / 100, "every_steps": None,
                                               "history_every": 10}}
    if material:
        changes["materials"] = {"bar": material}
    return changes, (t1, t2)


def pulse_error(out_dir: str, times: tuple[float, float]) -> float:
    """max |u(x, t2) − u(x − c0(t2 − t1), t1)| / max |u(·, t1)| (d'Alembert transport)."""
    run = Run(out_dir)
    chain = Chain(run)
    order = np.argsort(run.x[:, 0])
    x = run.x[order, 0]
    i1 = int(np.argmin(np.abs(run.times - times[0])))
    i2 = int(np.argmin(np.abs(run.times - times[1])))
    u1 = run.frame(i1).displacement[order, 0]
    u2 = run.frame(i2).displacement[order, 0]
    shift = chain.c0() * (run.times[i2] - run.times[i1])
    ref = np.interp(x - shift, x, u1, left=0.0, right=0.0)
    valid = x - shift > 0.05
    return float(np.max(np.abs(u2[valid] - ref[valid])) / np.max(np.abs(u1)))


PULSE_DX = (2.0e-3, 1.0e-3, 5.0e-4)      # δ = 3.015 dx: 6, 3, 1.5 mm at m = 3
PULSE_M = (2.015, 3.015, 4.015)          # horizon factors at dx = 1 mm (m = 2, 3, 4)
SINUSOID_DX = 1.0e-3


def run_all(work: str) -> dict:
    """Every run of the wave checks into work/: the sinusoid and the pulses. Returns the numbers."""
    changes, omega = sinusoid_changes(dx=SINUSOID_DX)
    out, _ = run_case("wave", os.path.join(work, "sinusoid"), changes, figures=False, source=MODELS)
    measured, discrete, c0, frames = measured_phase_speed(out, omega)
    result = {"sinusoid": {"out": out, "omega": omega, "measured": measured, "discrete": discrete, "c0": c0,
                           "frames": frames}, "pulse_dx": [], "pulse_m": []}
    for dx in PULSE_DX:
        ch, times = pulse_changes(dx)
        out, _ = run_case("wave", os.path.join(work, f"pulse_dx{dx * 1e3:g}mm"), ch, figures=False, source=MODELS)
        result["pulse_dx"].append((dx, 3.015 * dx, pulse_error(out, times), out, times))
    for factor in PULSE_M:
        ch, times = pulse_changes(1.0e-3, factor)
        out, _ = run_case("wave", os.path.join(work, f"pulse_m{factor:g}"), ch, figures=False, source=MODELS)
        result["pulse_m"].append((factor, factor * 1.0e-3, pulse_error(out, times), out, times))
    return result


def checks_from(result: dict, case: str = "wave") -> list[Check]:
    s = result["sinusoid"]
    rel = s["measured"] / s["discrete"] - 1.0
    chain_k = K_DELTA
    rows = [Check(case, f"phase speed ω/k of a driven sinusoid, kδ = {chain_k:g}, m = 3 [m/s] "
                        f"({s['frames']} frames, k fitted over ≥ 20 wavelengths)",
                  f"discrete C2 relation with Verlet phase {s['discrete']:.4f} ± 0.1 %", s["measured"],
                  bool(abs(rel) <= PHASE_TOLERANCE),
                  note=f"relative error {rel:+.2e}; v/c0 = {s['measured'] / s['c0']:.4f} "
                       f"(c0 = {s['c0']:.2f} m/s, the chain's long-wave speed)")]
    errors = [e for _dx, _d, e, _o, _t in result["pulse_dx"]]
    deltas = [d for _dx, d, _e, _o, _t in result["pulse_dx"]]
    rates = [np.log(errors[i] / errors[i + 1]) / np.log(deltas[i] / deltas[i + 1]) for i in range(len(errors) - 1)]
    rows.append(Check(case, "Gaussian pulse vs d'Alembert transport at c0, max error / amplitude, m = 3, "
                            f"δ = {', '.join(f'{d * 1e3:g}' for d in deltas)} mm",
                      "falls as δ shrinks (C2: order 2)", ", ".join(f"{e:.3g}" for e in errors),
                      bool(all(errors[i + 1] < errors[i] for i in range(len(errors) - 1)))))
    rows.append(Check(case, "observed order of the pulse error in δ (successive pairs)", "≥ 1.5 (C2: 2)",
                      ", ".join(f"{r:.2f}" for r in rates), bool(min(rates) >= 1.5)))
    return rows


def figure(result: dict, path: str):
    from postprocess.plotting import new_figure, save_figure
    fig, axes = new_figure(2, 1, size=(7.0, 9.0))
    fig.subplots_adjust(hspace=0.35)
    s = result["sinusoid"]
    run = Run(s["out"])
    chain = Chain(run)
    ax = axes[0, 0]
    kd = np.linspace(0.02, 5.0, 200)
    v_discrete = [chain.omega_space(q / chain.delta) / (q / chain.delta) / chain.c0() for q in kd]
    from scipy.special import sici
    cin = lambda z: np.euler_gamma + np.log(z) - sici(z)[1]
    ax.plot(kd, np.sqrt(4 * cin(kd)) / kd, "k--", lw=1, label="continuum PD, v/c0 = √(4 Cin(kδ))/(kδ)")
    ax.plot(kd, v_discrete, "C0-", lw=1, label="discrete chain, m = 3 (lattice sum), exact in time")
    v_verlet = [2 / chain.dt * np.arcsin(min(1.0, chain.omega_space(q / chain.delta) * chain.dt / 2))
                / (q / chain.delta) / chain.c0() for q in kd]
    ax.plot(kd, v_verlet, "C2-", lw=1, label=f"discrete chain + velocity Verlet, Δt = {chain.dt * 1e6:.3g} µs")
    k_meas = s["omega"] / s["measured"]
    ax.plot([k_meas * chain.delta], [s["measured"] / chain.c0()], "o", color="C3",
            label=f"measured: {s['measured']:.3f} m/s ({s['measured'] / s['discrete'] - 1:+.1e} vs discrete)")
    ax.set_xlabel("kδ")
    ax.set_ylabel("phase speed / c0")
    ax.set_title("wave: dispersion of the 1D chain (docs/theory.md C2)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax = axes[1, 0]
    for dx, delta, err, out, times in result["pulse_dx"]:
        r = Run(out)
        order = np.argsort(r.x[:, 0])
        i2 = int(np.argmin(np.abs(r.times - times[1])))
        ax.plot(r.x[order, 0] * 1e3, r.frame(i2).displacement[order, 0] * 1e6, lw=1,
                label=f"δ = {delta * 1e3:g} mm: error {err:.3g}")
    r = Run(result["pulse_dx"][-1][3])
    order = np.argsort(r.x[:, 0])
    t1, t2 = result["pulse_dx"][-1][4]
    i1, i2 = int(np.argmin(np.abs(r.times - t1))), int(np.argmin(np.abs(r.times - t2)))
    shift = Chain(r).c0() * (r.times[i2] - r.times[i1])
    ax.plot((r.x[order, 0] + shift) * 1e3, r.frame(i1).displacement[order, 0] * 1e6, "k--", lw=1,
            label="d'Alembert: the δ = 1.5 mm shape at t1, moved by c0(t2 − t1)")
    ax.set_xlim(300, 700)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("u_x [µm]")
    ax.set_title("Gaussian pulse after 0.4 m, m = 3")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    save_figure(fig, path)


def validate(report_dir: str) -> list[Check]:
    result = run_all(os.path.join(report_dir, "work", "wave"))
    figure(result, os.path.join(report_dir, "wave.png"))
    validate.result = result          # for the convergence figure
    return checks_from(result)
