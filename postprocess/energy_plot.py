"""energy.png: the energy terms of history.csv against time, and the balance that should stay constant.

The balance is every stored and dissipated energy minus the work put in (docs/theory.md C4):
    kinetic + strain + contact + indenter + broken bonds + damping work − external work,
each term where history.csv has its column (formats.md §4). Without breaking, its drift is the
integrator's error; with breaking, broken_bond_energy is the energy the broken bonds took with them,
and leaving it out shows a loss that is not one (branching: −4.6 % instead of 1.2 %). A quasi-static
load step books what its jump to equilibrium gives up as damping work (the solver's run/loop.cpp)
and holds no kinetic energy (its velocity is its mean rate), so the balance is flat across load
steps and its drift is the dynamic steps' error.
"""
from __future__ import annotations

import numpy as np

from .casefile import CaseSettings
from .plotting import new_figure, place_legend, plain_ticks, save_figure, short_title, si_scale, time_axis

# (history.csv column, legend label) of the terms on the stored/dissipated side of the balance.
STORED_TERMS = (("kinetic_energy", "kinetic"), ("strain_energy", "strain"), ("contact_energy", "contact"),
                ("indenter_energy", "indenter"), ("broken_bond_energy", "broken bonds"),
                ("damping_work", "damping work"))


def load_step_rows(history: dict) -> np.ndarray | bool:
    """Per row, whether it is a quasi-static load step's (`mode` 1); False without a mode column."""
    return np.asarray(history["mode"]) == 1 if "mode" in history else False


def balance_terms(history: dict) -> list[tuple[str, str]]:
    """The (column, label) of STORED_TERMS that history.csv has. A run with quasi-static load steps
    (`mode` 1) books in damping_work what their jumps to equilibrium give up, damped or not: its
    label says so."""
    load_steps = bool(np.any(load_step_rows(history)))
    return [(column, "damping work + given up by load steps" if column == "damping_work" and load_steps else label)
            for column, label in STORED_TERMS if column in history]


def energy_balance(history: dict) -> np.ndarray:
    """Σ stored and dissipated terms − external work [J]: constant up to the integrator's error. A
    quasi-static load step's row (`mode` 1) counts no kinetic energy: its velocity is the step's mean
    rate, which the static balance leaves out (the solver's run/loop.cpp)."""
    load_step = load_step_rows(history)

    def term(column):
        return np.where(load_step, 0.0, history[column]) if column == "kinetic_energy" else history[column]

    return sum(term(column) for column, _ in balance_terms(history)) - history["external_work"]


def balance_error(history: dict) -> tuple[np.ndarray, float, str]:
    """(drift of the balance from its first value relative to a reference energy, the reference [J],
    what the reference is). The reference is |external work| at the end when work was put in
    (then the last value is validation's |KE + U + E_broken + D − W| / W, branching.py), else the
    largest total energy of the run (a body set moving by its initial velocity)."""
    balance = energy_balance(history)
    work = float(history["external_work"][-1])
    if work != 0.0:
        return (balance - balance[0]) / abs(work), abs(work), "|W_ext| at the end"
    stored = sum(history[column] for column, _ in balance_terms(history) if column != "damping_work")
    reference = float(np.max(np.abs(stored))) or 1.0
    return (balance - balance[0]) / reference, reference, "the largest stored energy"


def plot_energy(history: dict, case: CaseSettings, path: str) -> str:
    """Top: every term against time. Bottom: the drift of the balance in % of the reference.
    Returns a one-line description of what was drawn."""
    t, t_label = time_axis(history["time"])
    terms = balance_terms(history)
    columns = [column for column, _ in terms] + ["external_work"]
    factor, unit = si_scale(np.concatenate([history[c] for c in columns]), "J")
    balance = energy_balance(history)
    drift, _, reference = balance_error(history)
    fig, axes = new_figure(2, 1, size=(7.5, 7.0), sharex=True, gridspec_kw={"height_ratios": [3, 1.4]})
    top, bottom = axes[0, 0], axes[1, 0]
    drawn = []
    for column, label in terms + [("external_work", "external work")]:
        if column in ("kinetic_energy", "strain_energy", "external_work") or np.any(history[column] != 0.0):
            top.plot(t, history[column] * factor, label=label)
            drawn.append(label)
    top.plot(t, balance * factor, "k--", linewidth=1.0, label="balance: Σ terms − external work")
    top.set_ylabel(f"energy [{unit}]")
    top.set_title(short_title(case, "energy"))
    top.grid(alpha=0.3)
    plain_ticks(top)
    place_legend(top, fontsize="small")
    bottom.plot(t, 100.0 * drift, "k-")
    bottom.set_ylabel("balance drift [%]")
    bottom.set_xlabel(t_label)
    bottom.grid(alpha=0.3)
    plain_ticks(bottom)
    end = 100.0 * float(drift[-1])
    bottom.set_title(f"drift at the end: {end:+.3g} % of {reference}", fontsize="small")
    fig.tight_layout()
    save_figure(fig, path, case.dpi)
    return f"energy.png: {', '.join(drawn)} and their balance (drift at the end {end:+.3g} % of {reference})"
