"""reaction_force.png: the reaction force of each node set listed in `output.reactions` (history.csv
columns reaction_<set>_fx, _fy, _fz of pipeline/formats.md §4) against the displacement that the
set's boundary condition prescribes: the force–displacement curve of a tensile test."""
from __future__ import annotations

import json

import numpy as np

from .casefile import CaseSettings
from .history import vector_column_names
from .plotting import new_figure, place_legend, plain_ticks, save_figure, short_title, si_scale, time_axis

def reaction_sets(history: dict) -> list[str]:
    """Node sets that have all three reaction columns, in column order."""
    return vector_column_names(history, "reaction")


def _table_value(times, values, t):
    """The piecewise-linear table of formats.md §3, held constant outside, at times t."""
    return np.interp(t, times, values) if len(times) > 1 else np.full_like(t, values[0])


def _table_integral(times, values, t):
    """∫_0^t of the piecewise-linear table (exact: cumulative trapezoids on a fine merge of the
    breakpoints and the requested times)."""
    grid = np.union1d(np.concatenate(([0.0], np.asarray(times, float))), t)
    grid = grid[grid >= 0.0]
    v = _table_value(times, values, grid)
    cumulative = np.concatenate(([0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(grid))))
    return np.interp(t, grid, cumulative)


def prescribed_displacement(case_json: dict, set_name: str, t: np.ndarray) -> dict[int, np.ndarray]:
    """Component → displacement of `set_name` at times t, from its displacement or velocity
    conditions in case.json (a velocity is integrated from t = 0; an initial displacement of the
    set is not included)."""
    out = {}
    for bc in case_json.get("boundary_conditions", []):
        if bc.get("set") != set_name or bc.get("kind") not in ("displacement", "velocity"):
            continue
        times, values = bc["times"], bc["values"]
        out[int(bc["component"])] = (_table_value(times, values, t) if bc["kind"] == "displacement"
                                     else _table_integral(times, values, t))
    return out


def plot_reactions(history: dict, case: CaseSettings, case_json_path: str, path: str):
    """One panel per set: each non-zero reaction component against the set's prescribed
    displacement in the component that moves most (against time if nothing moves)."""
    with open(case_json_path, encoding="utf-8") as stream:
        case_json = json.load(stream)
    names = reaction_sets(history)
    t = history["time"]
    factor, unit = si_scale(np.concatenate([history[f"reaction_{n}_f{a}"] for n in names for a in "xyz"]), "N")
    fig, axes = new_figure(len(names), 1, size=(7.0, 3.6 * len(names) + 0.8))
    for row, name in enumerate(names):
        ax = axes[row, 0]
        moves = prescribed_displacement(case_json, name, t)
        moving = {c: u for c, u in moves.items() if np.any(u != 0.0)}
        if moving:
            comp = max(moving, key=lambda c: np.abs(moving[c]).max())
            scale, length_unit = si_scale(moving[comp], "m")
            x, xlabel = moving[comp] * scale, f"prescribed displacement u{'xyz'[comp]} of '{name}' [{length_unit}]"
        else:
            x, xlabel = time_axis(t)
        for axis in "xyz":
            values = history[f"reaction_{name}_f{axis}"]
            if np.any(values != 0.0):
                ax.plot(x, values * factor, label=f"F{axis}")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f"reaction force [{unit}]")
        ax.set_title(short_title(case, f"reaction on '{name}'"))
        ax.grid(alpha=0.3)
        plain_ticks(ax)
        if ax.get_lines():
            place_legend(ax, fontsize="small")
    fig.tight_layout()
    save_figure(fig, path, case.dpi)
    return f"reaction_force.png: reaction force on node set(s) {', '.join(names)}"
