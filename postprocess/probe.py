"""probe.png: the displacement history at the probe (figures.probe: a point, a node set, or by
default the node nearest the centre of the box): from history.csv's probe columns at every history
row when the solver recorded the set (output.probes, formats.md §4), else sampled at the frames."""
from __future__ import annotations

import numpy as np

from .casefile import AXES, CaseSettings
from .plotting import new_figure, place_legend, plain_ticks, save_figure, short_title, si_scale, time_axis


def probe_from_history(history: dict, case: CaseSettings):
    """(times, values, where) of the probe from history.csv's probe_<set>_u<axis> columns, or None
    when the solver did not record it: figures.probe names a set of output.probes, or, with no
    figures.probe, the first set of output.probes is drawn (every history row: no aliasing of a
    motion faster than the frames)."""
    axis = AXES[case.component]
    recorded = [name[len("probe_"):-len("_ux")] for name in history if name.startswith("probe_") and name.endswith("_ux")]
    if isinstance(case.probe, str) and case.probe in recorded:
        chosen = case.probe
    elif case.probe is None and recorded:
        chosen = recorded[0]
    else:
        return None
    return (np.asarray(history["time"]), np.asarray(history[f"probe_{chosen}_u{axis}"]),
            f"volume-weighted mean of '{chosen}'")


def plot_probe(times, values, case: CaseSettings, path: str, *, where: str, position=None,
               samples: str = "frames") -> str:
    """u_component(t) at the probe; `where` says which nodes, `position` [m] the one node's place,
    `samples` what the points are (frames or history rows)."""
    axis = AXES[case.component]
    t, t_label = time_axis(times)
    factor, unit = si_scale(values, "m")
    fig, axes = new_figure(size=(7.5, 4.5))
    ax = axes[0, 0]
    if position is not None:
        length, length_unit = si_scale(position, "m")
        where += " at (" + ", ".join(f"{c * length:.4g}" for c in position) + f") {length_unit}"
    ax.plot(t, np.asarray(values) * factor, marker="." if len(times) <= 200 and samples == "frames" else None, label=where)
    ax.axhline(0.0, color="0.6", linewidth=0.6)
    ax.set_xlabel(t_label)
    ax.set_ylabel(f"displacement u_{axis} [{unit}]")
    ax.set_title(short_title(case, f"u_{axis} at the probe"))
    ax.grid(alpha=0.3)
    plain_ticks(ax)
    place_legend(ax, fontsize="small")
    fig.tight_layout()
    save_figure(fig, path, case.dpi)
    return f"probe.png: u_{axis} of {where} over {len(times)} {samples}"
