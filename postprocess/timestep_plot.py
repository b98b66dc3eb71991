"""timestep.png: the step size and the fixed-point iteration count K, like the thesis's membrane
figures (§5.1: time step against step, and K against step)."""
from __future__ import annotations

import numpy as np

from .casefile import CaseSettings
from .plotting import new_figure, save_figure


def plot_timestep(history: dict, case: CaseSettings, path: str):
    """dt against step and against time; K (and rejected attempts, if any) against step.

    A row at step 0 (the initial state, no step taken yet) is left out: its dt and K mean nothing.
    """
    taken = history["step"] > 0
    if not np.any(taken):
        taken = np.ones_like(taken)
    history = {name: values[taken] for name, values in history.items()}
    step, t, dt = history["step"], history["time"], history["dt"]
    fig, axes = new_figure(3, 1, size=(7.5, 8.5))
    a, b, c = axes[:, 0]
    marker = "." if len(step) <= 2000 else None
    a.plot(step, dt, marker=marker, linewidth=0.8)
    a.set_xlabel("step")
    a.set_ylabel("time step Δt [s]")
    a.set_title(f"{case.heading}: time step and iterations")
    if "mode" in history:
        # The mixed scheme (integrators/mixed.hpp): its load steps and explicit steps differ by
        # orders of magnitude, so Δt is drawn on a log scale with each mode in its own colour.
        for value, label in ((1, "quasi-static load steps"), (0, "explicit (Verlet) steps")):
            chosen = history["mode"] == value
            if np.any(chosen):
                b.plot(t[chosen], dt[chosen], ".", markersize=3, label=label)
        b.set_yscale("log")
        b.legend(fontsize="small", loc="best")
        a.set_yscale("log")
    else:
        b.plot(t, dt, marker=marker, linewidth=0.8)
    b.set_xlabel("time t [s]")
    b.set_ylabel("time step Δt [s]")
    c.plot(step, history["iterations"], marker=marker, linewidth=0.8, drawstyle="steps-pre",
           label="fixed-point iterations K")
    if np.any(history["rejected"] != 0):
        c.plot(step, history["rejected"], marker=marker, linewidth=0.8, drawstyle="steps-pre",
               label="rejected attempts")
        c.legend(fontsize="small")
        c.set_ylabel("iterations K, rejections [–]")
    else:
        c.set_ylabel("iterations K [–]")
    c.set_xlabel("step")
    c.yaxis.get_major_locator().set_params(integer=True)
    top = max(int(np.max(history["iterations"])), int(np.max(history["rejected"])), 1)
    c.set_ylim(-0.2, top + 0.5)
    for ax in axes[:, 0]:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path)
