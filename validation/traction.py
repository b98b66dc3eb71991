"""Checks of cases/traction (thesis §5.3): the dog-bone breaks in its gauge section, the crack runs
within 10° of perpendicular to the load, and the pulled grip's force falls to (almost) nothing
once the specimen is cut through; the peak of the force–displacement curve is reported."""
from __future__ import annotations

import numpy as np

from .common import Check, Run, angle_from_axis, principal_direction
from .runner import geometry_parameters

ANGLE_DEGREES = 10.0
RESIDUAL_FRACTION = 0.1  # after failure the grip carries < 10 % of the peak force


def crack_clusters(run: Run, threshold: float = 0.3) -> list[np.ndarray]:
    """The strongly damaged nodes (damage > threshold) of the last frame, split into cracks where
    their x coordinates leave a gap wider than 2δ (the load is along x, the cracks across it)."""
    damaged = np.flatnonzero(run.frame(-1).damage > threshold)
    if damaged.size == 0:
        return []
    order = damaged[np.argsort(run.x[damaged, 0])]
    gaps = np.flatnonzero(np.diff(run.x[order, 0]) > 2.0 * run.horizon)
    return [c for c in np.split(order, gaps + 1) if c.size >= 5]


def force_curve(run: Run, set_name: str = "right") -> tuple[np.ndarray, np.ndarray]:
    """(grip displacement, reaction force F_x) of the pulled grip, from history.csv and the
    grip's velocity table in case.json."""
    from postprocess.reaction_plot import prescribed_displacement
    t = run.history["time"]
    u = prescribed_displacement(run.case, set_name, t)[0]
    return u, run.history[f"reaction_{set_name}_fx"]


def checks(out_dir: str, case: str = "traction") -> list[Check]:
    run = Run(out_dir)
    params = geometry_parameters(out_dir)
    lo = params["L"] / 2 - params["Lgs"] / 2
    hi = params["L"] / 2 + params["Lgs"] / 2
    rows = []
    clusters = crack_clusters(run)
    rows.append(Check(case, "cracks across the specimen (damage > 0.3 clusters)", "≥ 1",
                      len(clusters), len(clusters) >= 1))
    for k, nodes in enumerate(clusters):
        xs = run.x[nodes, 0]
        rows.append(Check(case, f"crack {k + 1}: x range [mm]", f"inside the gauge [{lo * 1e3:.4g}, {hi * 1e3:.4g}]",
                          f"{xs.min() * 1e3:.4g}–{xs.max() * 1e3:.4g}", bool(xs.min() >= lo and xs.max() <= hi)))
        angle = float(angle_from_axis(principal_direction(run.x[nodes])[None, :], np.array([0.0, 1.0]))[0])
        rows.append(Check(case, f"crack {k + 1}: angle from ⊥ load [°]", f"≤ {ANGLE_DEGREES:g}", angle,
                          angle <= ANGLE_DEGREES))
    u, force = force_curve(run)
    peak = int(np.argmax(force))
    rows.append(Check(case, "peak reaction force [N] at grip displacement [mm]", "reported",
                      f"{force[peak]:.4g} N at {u[peak] * 1e3:.4g} mm", True))
    final = float(abs(force[-1]))
    rows.append(Check(case, "reaction at the end / peak (cut through)", f"< {RESIDUAL_FRACTION:g}",
                      final / force[peak], final < RESIDUAL_FRACTION * force[peak]))
    return rows
