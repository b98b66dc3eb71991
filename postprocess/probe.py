"""probe.png: the displacement history at the probe (figures.probe: a point, a node set, or by
default the node nearest the centre of the box), from the frames."""
from __future__ import annotations

import numpy as np

from .casefile import AXES, CaseSettings
from .plotting import new_figure, place_legend, plain_ticks, save_figure, short_title, si_scale, time_axis


def plot_probe(times, values, case: CaseSettings, path: str, *, where: str, position=None) -> str:
    """u_component(t) at the probe; `where` says which nodes, `position` [m] the one node's place."""
    axis = AXES[case.component]
    t, t_label = time_axis(times)
    factor, unit = si_scale(values, "m")
    fig, axes = new_figure(size=(7.5, 4.5))
    ax = axes[0, 0]
    if position is not None:
        length, length_unit = si_scale(position, "m")
        where += " at (" + ", ".join(f"{c * length:.4g}" for c in position) + f") {length_unit}"
    ax.plot(t, np.asarray(values) * factor, marker="." if len(times) <= 200 else None, label=where)
    ax.axhline(0.0, color="0.6", linewidth=0.6)
    ax.set_xlabel(t_label)
    ax.set_ylabel(f"displacement u_{axis} [{unit}]")
    ax.set_title(short_title(case, f"u_{axis} at the probe"))
    ax.grid(alpha=0.3)
    plain_ticks(ax)
    place_legend(ax, fontsize="small")
    fig.tight_layout()
    save_figure(fig, path, case.dpi)
    return f"probe.png: u_{axis} of {where} over {len(times)} frames"
