"""indenter_force.png: the reaction force on each rigid indenter against time (history.csv columns
indenter_<name>_fx, _fy, _fz of pipeline/formats.md §4), drawn only when the case has indenters."""
from __future__ import annotations

import numpy as np

from .casefile import CaseSettings
from .history import vector_column_names
from .plotting import new_figure, save_figure

def indenter_names(history: dict) -> list[str]:
    """Names of the indenters that have all three force columns, in column order."""
    return vector_column_names(history, "indenter")


def plot_indenter_forces(history: dict, case: CaseSettings, path: str):
    """One panel per indenter: the three components and the magnitude of the reaction [N]."""
    names = indenter_names(history)
    t = history["time"]
    fig, axes = new_figure(len(names), 1, size=(7.5, 3.2 * len(names) + 0.8), sharex=True)
    for row, name in enumerate(names):
        ax = axes[row, 0]
        components = [history[f"indenter_{name}_f{axis}"] for axis in "xyz"]
        for axis, values in zip("xyz", components):
            if np.any(values != 0.0):
                ax.plot(t, values, label=f"F{axis}")
        ax.plot(t, np.sqrt(sum(c * c for c in components)), "k--", label="|F|")
        ax.set_ylabel("reaction force [N]")
        ax.set_title(f"{case.heading}: indenter '{name}'")
        ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time t [s]")
    fig.tight_layout()
    save_figure(fig, path)
