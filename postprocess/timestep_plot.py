"""timestep.png: what the time integrator did, drawn per integrator (time.integrator).

- verlet: Δt is a constant, so three panels of it said nothing. Drawn instead: Δt against the
  stability limits run.log reports (thesis eq. 2.5 and, when computed, the exact limit 2/ω_max),
  with the margin Δt/Δt_limit in the title, the steps shortened to land on an output time as points
  of their own, and the wall-clock time against simulated time (the run's speed, and where it
  slowed down).
- adaptive, quasi_static: Δt against step and against time, and the fixed-point or Newton
  iterations K with rejected attempts against step, like the thesis's membrane figures (§5.1).
- mixed: the same with Δt on a log scale, quasi-static and explicit steps in their own colours.
"""
from __future__ import annotations

import os
import re

import numpy as np

from .casefile import CaseSettings
from .plotting import new_figure, place_legend, plain_ticks, save_figure, short_title, si_scale, time_axis

# run.log's setup line (solver/src/run/prepare.cpp log_setup): "dt 5.68e-07 s (stable 7.1e-07 s × …"
# or "(exact limit 1.2e-06 s = 1.7 × eq. 2.5, × safety factor 0.8)" or "(fixed; stable 7.1e-07 s)".
DT_LINE = re.compile(r"^dt (\S+) s \((.*)\)")
STABLE = re.compile(r"stable (\S+) s")
EXACT = re.compile(r"exact limit (\S+) s = (\S+) × eq\. 2\.5")


def stability_limits(run_log: str) -> dict[str, float]:
    """{"eq. 2.5": Δt_stable, "exact 2/ω_max": Δt_exact} as far as run.log states them; {} without run.log."""
    try:
        with open(run_log, encoding="utf-8", errors="replace") as stream:
            lines = stream.read().splitlines()
    except OSError:
        return {}
    for line in lines:
        match = DT_LINE.match(line)
        if not match:
            continue
        found = {}
        detail = match.group(2)
        if (exact := EXACT.search(detail)):
            found["exact 2/ω_max"] = float(exact.group(1))
            found["eq. 2.5"] = float(exact.group(1)) / float(exact.group(2))
        elif (stable := STABLE.search(detail)):
            found["eq. 2.5"] = float(stable.group(1))
        return found
    return {}


def _taken(history: dict) -> dict:
    """The rows of steps taken: a row at step 0 (the initial state) has no meaningful dt or K."""
    taken = history["step"] > 0
    if not np.any(taken):
        taken = np.ones_like(taken, dtype=bool)
    return {name: values[taken] for name, values in history.items()}


def plot_timestep(history: dict, case: CaseSettings, path: str, run_log: str | None = None) -> str:
    """Draw timestep.png for the case's integrator; returns a one-line description."""
    history = _taken(history)
    integrator = getattr(case, "integrator", None)
    if integrator == "verlet":
        limits = stability_limits(run_log or os.path.join(os.path.dirname(os.path.dirname(path)), "run.log"))
        return _plot_verlet(history, case, path, limits)
    return _plot_controlled(history, case, path)


def _plot_verlet(history: dict, case, path: str, limits: dict) -> str:
    t, t_label = time_axis(history["time"])
    dt = history["dt"]
    factor, unit = si_scale(np.concatenate([dt, list(limits.values())]), "s")
    fig, axes = new_figure(2, 1, size=(7.5, 6.5), sharex=True)
    a, b = axes[:, 0]
    # The loop shortens the step that would pass an output time so that it lands on it (run/schedule):
    # drawn as one line, those steps read as spikes of instability. So the step the rule gives is the
    # line, and the shortened steps are points of their own, counted in the legend.
    nominal = float(np.max(dt))
    shortened = dt < nominal * (1.0 - 1e-9)
    a.plot(t, np.full_like(dt, nominal) * factor, linewidth=1.5, label="time step Δt")
    if np.any(shortened):
        a.plot(t[shortened], dt[shortened] * factor, linestyle="none", marker=".", markersize=3,
               color="C1", label=f"{int(np.count_nonzero(shortened))} steps shortened to land on an output time")
    margins = []
    for (name, limit), style in zip(limits.items(), ("--", ":")):
        a.axhline(limit * factor, color="C3", linestyle=style, linewidth=1.0, label=f"stable limit, {name}")
        margins.append(f"{float(np.max(dt)) / limit:.3g} × {name}")
    a.set_ylim(0.0, 1.15 * float(max([np.max(dt)] + list(limits.values()))) * factor)
    a.set_ylabel(f"time step Δt [{unit}]")
    a.set_title(short_title(case, "Verlet, Δt = " + (", ".join(margins) if margins else "constant")))
    a.grid(alpha=0.3)
    plain_ticks(a)
    place_legend(a, fontsize="small")
    wall = history["wall_time"]
    w_factor, w_unit = si_scale(wall, "s")
    b.plot(t, wall * w_factor, linewidth=1.0)
    b.set_xlabel(t_label)
    b.set_ylabel(f"wall-clock time [{w_unit}]")
    steps = int(history["step"][-1])
    rate = steps / float(wall[-1]) if wall[-1] > 0 else float("nan")
    b.set_title(f"{steps} steps, {rate:.3g} steps per second of wall time", fontsize="small")
    b.grid(alpha=0.3)
    plain_ticks(b)
    fig.tight_layout()
    save_figure(fig, path, case.dpi)
    return "timestep.png: Verlet's constant Δt against its stability limit" + (
        f" ({', '.join(margins)})" if margins else " (no run.log: limits unknown)") + ", and the wall-clock time"


def _plot_controlled(history: dict, case, path: str) -> str:
    step, dt = history["step"], history["dt"]
    t, t_label = time_axis(history["time"])
    # Every history.csv has `mode` since issue 16 (0 for a dynamic step): the mixed scheme is the one
    # with both kinds of step, or the one the case names.
    mode = history.get("mode")
    mixed = getattr(case, "integrator", None) == "mixed" or (
        mode is not None and bool(np.any(mode == 1)) and bool(np.any(mode == 0)))
    factor, unit = si_scale(dt, "s")
    fig, axes = new_figure(3, 1, size=(7.5, 8.5))
    a, b, c = axes[:, 0]
    marker = "." if len(step) <= 2000 else None
    a.plot(step, dt * factor, marker=marker, linewidth=0.8)
    a.set_xlabel("step")
    a.set_ylabel(f"time step Δt [{unit}]")
    what = {"adaptive": "adaptive step", "quasi_static": "quasi-static load steps",
            "mixed": "mixed: load and explicit steps"}.get(getattr(case, "integrator", None) or "", "time step")
    a.set_title(short_title(case, what))
    if mixed:
        # The mixed scheme (integrators/mixed.hpp): its load steps and explicit steps differ by
        # orders of magnitude, so Δt is drawn on a log scale with each mode in its own colour.
        for value, label in ((1, "quasi-static load steps"), (2, "implicit (generalized-α) steps"),
                             (0, "explicit (Verlet) steps")):
            chosen = history["mode"] == value
            if np.any(chosen):
                b.plot(t[chosen], dt[chosen] * factor, ".", markersize=3, label=label)
        b.set_yscale("log")
        a.set_yscale("log")
    else:
        b.plot(t, dt * factor, marker=marker, linewidth=0.8)
    b.set_xlabel(t_label)
    b.set_ylabel(f"time step Δt [{unit}]")
    c.plot(step, history["iterations"], marker=marker, linewidth=0.8, drawstyle="steps-pre",
           label="iterations K")
    rejected = np.any(history["rejected"] != 0)
    if rejected:
        c.plot(step, history["rejected"], marker=marker, linewidth=0.8, drawstyle="steps-pre",
               label="rejected attempts")
        c.set_ylabel("iterations K, rejections [–]")
    else:
        c.set_ylabel("iterations K [–]")
    c.set_xlabel("step")
    c.yaxis.get_major_locator().set_params(integer=True)
    top = max(int(np.max(history["iterations"])), int(np.max(history["rejected"])), 1)
    c.set_ylim(-0.2, top + 0.5)
    for ax in axes[:, 0]:
        ax.grid(alpha=0.3)
        plain_ticks(ax)
    if mixed:
        place_legend(b, fontsize="small")
    if rejected:
        place_legend(c, fontsize="small")
    fig.tight_layout()
    save_figure(fig, path, case.dpi)
    return (f"timestep.png: Δt of {len(step)} steps ({float(np.min(dt)):.3g} … {float(np.max(dt)):.3g} s), "
            f"iterations K (mean {float(np.mean(history['iterations'])):.3g})"
            + (f", {int(np.sum(history['rejected']))} rejected attempts" if rejected else "")
            + (", quasi-static and explicit steps in their own colours" if mixed else ""))
