"""probe.png: the displacement history of the node nearest to the geometric centre, from the frames."""
from __future__ import annotations

import numpy as np

from .casefile import AXES, CaseSettings
from .plotting import new_figure, save_figure


def plot_probe(times, values, case: CaseSettings, path: str, *, node: int, position):
    """u_component(t) of node `node` at reference `position` [m]."""
    axis = AXES[case.component]
    fig, axes = new_figure(size=(7.5, 4.5))
    ax = axes[0, 0]
    ax.plot(np.asarray(times), np.asarray(values), marker="." if len(times) <= 200 else None)
    ax.axhline(0.0, color="0.6", linewidth=0.6)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel(f"displacement u_{axis} [m]")
    where = ", ".join(f"{c:.4g}" for c in position)
    ax.set_title(f"{case.heading}\nu_{axis} of the node nearest the centre: node {node} at ({where}) m",
                 fontsize="medium")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path)
