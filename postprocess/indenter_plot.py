"""indenter_force.png: the reaction force on each rigid indenter against time (history.csv columns
indenter_<name>_fx, _fy, _fz of pipeline/formats.md §4), drawn only when the case has indenters."""
from __future__ import annotations

import numpy as np

from .casefile import CaseSettings
from .history import vector_column_names
from .plotting import new_figure, place_legend, plain_ticks, save_figure, short_title, si_scale, time_axis

def indenter_names(history: dict) -> list[str]:
    """Names of the indenters that have all three force columns, in column order."""
    return vector_column_names(history, "indenter")


def plot_indenter_forces(history: dict, case: CaseSettings, path: str):
    """One panel per indenter: the three components and the magnitude of the reaction [N]."""
    names = indenter_names(history)
    t, t_label = time_axis(history["time"])
    factor, unit = si_scale(np.concatenate([history[f"indenter_{n}_f{a}"] for n in names for a in "xyz"]), "N")
    fig, axes = new_figure(len(names), 1, size=(7.5, 3.2 * len(names) + 0.8), sharex=True)
    for row, name in enumerate(names):
        ax = axes[row, 0]
        components = [history[f"indenter_{name}_f{axis}"] * factor for axis in "xyz"]
        for axis, values in zip("xyz", components):
            if np.any(values != 0.0):
                ax.plot(t, values, label=f"F{axis}")
        ax.plot(t, np.sqrt(sum(c * c for c in components)), "k--", label="|F|")
        ax.set_ylabel(f"reaction force [{unit}]")
        ax.set_title(short_title(case, f"indenter '{name}'"))
        ax.grid(alpha=0.3)
        plain_ticks(ax)
        place_legend(ax, fontsize="small")
    axes[-1, 0].set_xlabel(t_label)
    fig.tight_layout()
    save_figure(fig, path, case.dpi)
    return f"indenter_force.png: reaction force on indenter(s) {', '.join(names)}"
