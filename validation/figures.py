"""One PNG per case for out/validate/: the quantity each check is about, against its target."""
from __future__ import annotations

import os

import numpy as np

from postprocess.plotting import new_figure, save_figure

from . import branching, drum, plate_with_hole, three_point_bending, traction
from .common import Run


def plate_with_hole_figure(out_dir: str, path: str):
    """ε_xx/ε_far along the line x = x_c above the hole (the last frame before breakage) against
    Kirsch's infinite-plate profile σ_xx/σ = 1 + a²/(2r²) + 3a⁴/(2r⁴) (θ = 90°)."""
    run = Run(out_dir)
    centre, a, length, _ = plate_with_hole.geometry(run)
    ratio, index, far, _ = plate_with_hole.kirsch_ratio(run)
    frame, x = run.frame(index), run.x
    cols = np.abs(x[:, 0] - centre[0]) < 0.51 * run.dx
    r, e = [], []
    for y in np.unique(np.round(x[cols & (x[:, 1] > centre[1]), 1], 12)):
        row = cols & np.isclose(x[:, 1], y)
        left, right = row & (x[:, 0] < centre[0]), row & (x[:, 0] > centre[0])
        r.append((y - centre[1]) / a)
        e.append((frame.displacement[right, 0].mean() - frame.displacement[left, 0].mean()) /
                 (x[right, 0].mean() - x[left, 0].mean()) / far)
    rr = np.linspace(1.0, max(r), 200)
    fig, axes = new_figure()
    ax = axes[0, 0]
    ax.plot(r, e, "o", ms=3, label="peridynamics (node rows above the hole)")
    ax.plot(rr, 1 + 0.5 / rr ** 2 + 1.5 / rr ** 4, "k-", label="Kirsch, infinite plate")
    ax.axhspan(3 * 0.85, 3 * 1.15, color="g", alpha=0.1, label="3 ± 15 % (the check)")
    ax.set_xlabel("r / a on the line through the hole's centre ⊥ load")
    ax.set_ylabel("ε_xx / far-field ε_xx")
    ax.set_title(f"plate_with_hole: t = {run.times[index] * 1e3:.3g} ms, edge ratio {ratio:.3g}")
    ax.legend()
    ax.grid(alpha=0.3)
    save_figure(fig, path)


def traction_figure(out_dir: str, path: str):
    run = Run(out_dir)
    u, force = traction.force_curve(run)
    fig, axes = new_figure()
    ax = axes[0, 0]
    ax.plot(u * 1e3, force)
    ax.set_xlabel("grip displacement [mm]")
    ax.set_ylabel("reaction force on the pulled grip [N]")
    ax.set_title("traction: force–displacement")
    ax.grid(alpha=0.3)
    save_figure(fig, path)


def branching_figure(out_dir: str, path: str):
    run = Run(out_dir)
    t, speed = branching.tip_speeds(run)
    fig, axes = new_figure()
    ax = axes[0, 0]
    ax.plot(t * 1e6, speed, "o-", ms=3, label="crack tip (upper branch)")
    ax.axhline(branching.rayleigh_speed(run), color="r", ls="--", label="Rayleigh speed c_R")
    ax.set_xlabel("time [µs]")
    ax.set_ylabel(f"tip speed over {branching.SPEED_WINDOW * 1e6:g} µs [m/s]")
    ax.set_title(f"{os.path.basename(os.path.normpath(out_dir))}: crack-tip speed")
    ax.legend()
    ax.grid(alpha=0.3)
    save_figure(fig, path)


def drum_figure(out_dir: str, path: str):
    """The modal coordinate q(t) with the fitted sinusoid and the membrane formula's period marked,
    and the energy error against time."""
    run = Run(out_dir)
    t, q = drum.modal_coordinate(run)
    f_theory = drum.theory_frequency(run)
    f_zero, _ = drum.zero_crossing_frequency(t, q)
    f_fit = drum.fitted_frequency(t, q, f_zero)
    amplitude = np.max(np.abs(q))
    tt = np.linspace(0.0, t[-1], 2000)
    fig, axes = new_figure(2, 1, size=(7.0, 7.0))
    ax = axes[0, 0]
    ax.plot(t * 1e3, q * 1e6, "o", ms=3, label="peridynamics: modal coordinate of w")
    ax.plot(tt * 1e3, amplitude * np.sin(2 * np.pi * f_theory * tt) * 1e6, "k--", lw=1,
            label=f"membrane formula, f = {f_theory:.1f} Hz")
    ax.plot(tt * 1e3, amplitude * np.sin(2 * np.pi * f_fit * tt) * 1e6, "C1-", lw=1,
            label=f"fit, f = {f_fit:.1f} Hz ({f_fit / f_theory - 1:+.2%})")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("fundamental-mode amplitude [µm]")
    length, _ = drum.geometry(run)
    ax.set_title(f"drum: ε0 = {drum.pre_strain(run):g}, L/dx = {length / run.dx:.0f}, no damping")
    ax.legend(loc="lower left", fontsize=8)
    ax.grid(alpha=0.3)
    ax = axes[1, 0]
    h = run.history
    energy = h["kinetic_energy"] + h["strain_energy"] - h["external_work"] + h["damping_work"]
    ax.plot(h["time"] * 1e3, (energy - energy[0]) / h["kinetic_energy"][0])
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("(KE + U − W_ext − E(0)) / KE(0)")
    ax.grid(alpha=0.3)
    save_figure(fig, path)


def three_point_bending_figure(out_dir: str, path: str):
    """Load against the beam axis's deflection and the load-point displacement, with the elastic
    line of Timoshenko + the E399 notch compliance and LEFM's peak load."""
    run = Run(out_dir)
    spec = three_point_bending.Specimen(run, out_dir)
    u, force = three_point_bending.load_curve(run)
    delta = three_point_bending.axis_deflection(run, spec)
    p_frames = np.interp(run.times, run.history["time"], force)
    fig, axes = new_figure()
    ax = axes[0, 0]
    ax.plot(delta * 1e3, p_frames / 1e3, "o-", ms=3, label="P against the axis deflection δ (frames)")
    ax.plot(u * 1e3, force / 1e3, "-", lw=1, label="P against the load-point displacement")
    d = np.linspace(0.0, max(delta.max(), 1e-12), 50)
    ax.plot(d * 1e3, spec.stiffness() * d / 1e3, "k--", lw=1, label="Timoshenko beam + E399 notch compliance")
    ax.axhline(spec.lefm_peak() / 1e3, color="r", ls=":", label="LEFM P_c (K_Ic = √(G0 E'))")
    ax.set_xlabel("displacement [mm]")
    ax.set_ylabel("load P [kN]")
    ax.set_title("three_point_bending: steel SENB, LPS ν = 0.29")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    save_figure(fig, path)


FIGURES = {"plate_with_hole": plate_with_hole_figure, "three_point_bending": three_point_bending_figure, "traction": traction_figure, "branching": branching_figure,
           "drum": drum_figure}
