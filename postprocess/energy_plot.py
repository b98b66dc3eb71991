"""energy.png: the energy terms of history.csv against time, and the balance that should stay constant."""
from __future__ import annotations

import numpy as np

from .casefile import CaseSettings
from .plotting import new_figure, save_figure


def energy_balance(history: dict) -> np.ndarray:
    """kinetic + strain (+ contact) + damping work − external work [J]: constant in an exact
    integration without breaking. contact_energy is there only when the case has contact or
    indenters (formats.md §4)."""
    return (history["kinetic_energy"] + history["strain_energy"] + history.get("contact_energy", 0.0)
            + history["damping_work"] - history["external_work"])


def plot_energy(history: dict, case: CaseSettings, path: str):
    """Top: every term against time. Bottom: the drift of the balance from its first value."""
    t = history["time"]
    balance = energy_balance(history)
    fig, axes = new_figure(2, 1, size=(7.5, 7.0), sharex=True, gridspec_kw={"height_ratios": [3, 1.4]})
    top, bottom = axes[0, 0], axes[1, 0]
    top.plot(t, history["kinetic_energy"], label="kinetic energy")
    top.plot(t, history["strain_energy"], label="strain energy")
    top.plot(t, history["external_work"], label="external work")
    top.plot(t, history["damping_work"], label="damping work")
    contact = "contact_energy" in history
    if contact:
        top.plot(t, history["contact_energy"], label="contact energy")
    top.plot(t, balance, "k--", label="balance: kinetic + strain + " + ("contact + " if contact else "") +
             "damping − external")
    top.set_ylabel("energy [J]")
    top.set_title(f"{case.heading}: energy")
    top.legend(fontsize="small")
    top.grid(alpha=0.3)
    bottom.plot(t, balance - balance[0], "k-")
    bottom.set_ylabel("balance − balance(t₀) [J]")
    bottom.set_xlabel("time t [s]")
    bottom.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path)
