"""One PNG per case for out/validate/: the quantity each check is about, against its target."""
from __future__ import annotations

import numpy as np

from postprocess.plotting import new_figure, save_figure

from . import branching, plate_with_hole, traction
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
    ax.axhline(branching.RAYLEIGH, color="r", ls="--", label="Rayleigh speed c_R")
    ax.set_xlabel("time [µs]")
    ax.set_ylabel(f"tip speed over {branching.SPEED_WINDOW * 1e6:g} µs [m/s]")
    ax.set_title("branching: crack-tip speed")
    ax.legend()
    ax.grid(alpha=0.3)
    save_figure(fig, path)


FIGURES = {"plate_with_hole": plate_with_hole_figure, "traction": traction_figure, "branching": branching_figure}
