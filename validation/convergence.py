"""out/validate/convergence.png: how the static-tension strain error and the wave (pulse) error
change with the horizon δ at fixed m = δ/dx and with m at fixed dx, and the drum's frequency error
with dx, from the runs of static.py, wave.py and drum.py (their validate functions keep their
numbers in `.result`)."""
from __future__ import annotations

import numpy as np


def _finish(ax, xlabel: str, ylabel: str, title: str, grid: str):
    """Labels, title, legend and grid, the same for every panel."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which=grid)


def figure(static_result: dict | None, wave_result: dict | None, path: str, drum_result: list | None = None):
    from postprocess.plotting import new_figure, save_figure
    fig, axes = new_figure(1, 3, size=(16.0, 4.5))
    ax = axes[0, 0]
    if static_result:
        for key, label, marker in (("dx", "m = 3, δ varies (dx = 2, 1.5, 1 mm)", "o-"),
                                   ("m", "dx = 1 mm, m = 2, 3, 4, 5", "s--")):
            rows = sorted(static_result[key], key=lambda r: r["delta"])
            d = np.array([r["delta"] for r in rows]) * 1e3
            ax.plot(d, [abs(r["exx"] / r["exx0"] - 1) for r in rows], marker, label=f"ε_xx vs σ/E, {label}")
            ax.plot(d, [abs(r["exx"] / r["pxx"] - 1) for r in rows], marker, alpha=0.5, mfc="none",
                    label=f"ε_xx vs lattice sum, {label}")
            if key == "m":
                for r, x in zip(rows, d):
                    ax.annotate(f"m={r['m']:.0f}", (x, abs(r["exx"] / r["exx0"] - 1)), fontsize=7)
        ax.set_yscale("log")
    _finish(ax, "δ [mm]", "relative error of the interior strain", "static tension (C3): error vs δ and m", "both")
    ax = axes[0, 1]
    if wave_result:
        d = np.array([r[1] for r in wave_result["pulse_dx"]]) * 1e3
        e = np.array([r[2] for r in wave_result["pulse_dx"]])
        ax.loglog(d, e, "o-", label="m = 3, δ varies (dx = 2, 1, 0.5 mm)")
        ax.loglog(d, e[-1] * (d / d[-1]) ** 2, "k:", lw=1, label="slope 2")
        dm = np.array([r[1] for r in wave_result["pulse_m"]]) * 1e3
        em = np.array([r[2] for r in wave_result["pulse_m"]])
        ax.loglog(dm, em, "s--", label="dx = 1 mm, m = 2, 3, 4")
    _finish(ax, "δ [mm]", "max |u − d'Alembert| / amplitude", "Gaussian pulse after 0.4 m (C2): error vs δ and m",
            "both")
    ax = axes[0, 2]
    if drum_result:
        h = np.array([p[0] for p in drum_result])
        r = np.array([p[1] for p in drum_result])
        ax.plot(h, r - 1.0, "o-", label="drum, m = 3: f_PD/f − 1")
        slope, intercept = np.polyfit(h, r - 1.0, 1)
        hh = np.linspace(0.0, h.max(), 50)
        ax.plot(hh, intercept + slope * hh, "k:", lw=1, label=f"line {intercept:+.3f} {slope:+.2f}·dx/L")
        ax.axhline(np.sqrt(1.0254) - 1.0, color="C2", ls="--", lw=1, label="√R_W − 1 (C1 lattice sum, δ = 3.015 dx)")
    ax.axhline(0.0, color="k", lw=0.5)
    _finish(ax, "dx / L", "relative frequency error", "drum: fundamental frequency vs dx", "major")
    save_figure(fig, path)
