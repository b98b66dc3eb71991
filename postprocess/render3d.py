"""damage_3d.png: a rendered view of a 3D run's last frame, where the damage is inside the body.

With ParaView's pvpython on PATH (not a dependency: `apt-get install paraview`), the frame .vtu is
rendered offscreen (under xvfb-run when there is no X display: Debian's ParaView needs one) by postprocess/pvpython_damage.py: the body as translucent points, the damaged
nodes (φ > DAMAGED_SHOWN) as opaque spheres coloured by damage, seen from an oblique camera.
Without it, or when it fails, matplotlib draws the same: a light, sparse cloud of the body's nodes
for its shape and the damaged nodes coloured by damage, in the box's proportions (an axis thinner
than THIN_AXIS of the longest stretched to it, and the title says so).
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys

import numpy as np

from common.atomic import atomic_path

from .casefile import CaseSettings
from .plotting import DPI, plt, save_figure, short_title, si_scale

DAMAGED_SHOWN = 0.1      # damage above which a node is drawn as damaged (crack nodes: > 0.3)
THIN_AXIS = 0.2         # matplotlib: an axis drawn at least this share of the longest
CONTEXT_POINTS = 4000    # nodes of the body drawn (every k-th) to show its shape
PVPYTHON_TIMEOUT = 300   # s: a rendering that takes longer is abandoned for matplotlib
SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "pvpython_damage.py")


class _RenderFailed(Exception):
    pass


def damaged_nodes(damage) -> np.ndarray:
    """Indices of the nodes drawn as damaged."""
    return np.flatnonzero(np.asarray(damage) > DAMAGED_SHOWN)


def plot_damage_3d_matplotlib(points, damage, case: CaseSettings, path: str, *, time: float) -> str:
    """The matplotlib rendering (see the module docstring); returns what post-processing says."""
    points = np.asarray(points, dtype=np.float64)
    length, unit = si_scale(points, "m")
    p = points * length
    shown = damaged_nodes(damage)
    fig = plt.figure(figsize=(8.0, 6.0), dpi=DPI)
    ax = fig.add_subplot(projection="3d")
    # true proportions, except that an axis thinner than THIN_AXIS of the longest is stretched to it
    # (a 3 mm plate 40 mm long: its z ticks would overlap)
    true_extent = np.ptp(p, axis=0)
    extent = np.maximum(true_extent, THIN_AXIS * true_extent.max())
    ax.set_box_aspect(tuple(extent))
    stretched = [f"{a} ×{e / t:.2g}" for a, e, t in zip("xyz", extent, true_extent) if 0 < t and e > t * (1 + 1e-9)]
    stride = max(1, int(np.ceil(len(p) / CONTEXT_POINTS)))
    ax.scatter(p[::stride, 0], p[::stride, 1], p[::stride, 2], s=1.0, color="0.75", alpha=0.3, linewidths=0,
               depthshade=False, label="body")
    if len(shown):
        scatter = ax.scatter(p[shown, 0], p[shown, 1], p[shown, 2], c=np.asarray(damage)[shown], cmap="inferno_r",
                             vmin=0.0, vmax=1.0, s=4.0, linewidths=0, depthshade=False)
        fig.colorbar(scatter, ax=ax, shrink=0.6, pad=0.15, label="damage φ [-]")
    ax.view_init(elev=35.0, azim=-60.0)
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")
    ax.set_zlabel(f"z [{unit}]")
    ax.tick_params(labelsize="x-small")
    t_factor, t_unit = si_scale([time], "s")
    ax.set_title(short_title(case, f"damage at t = {time * t_factor:.4g} {t_unit}")
                 + (f"\n(drawn stretched: {', '.join(stretched)})" if stretched else ""))
    save_figure(fig, path, case.dpi)
    return (f"damage_3d.png (matplotlib): {len(shown)} nodes with damage > {DAMAGED_SHOWN:g} of {len(p)}"
            + ("" if shutil.which("pvpython") else "; pvpython not found: ParaView renders it when installed"))


def render_with_pvpython(frame_path: str, path: str, title: str, pvpython: str | None = None) -> str | None:
    """Render with ParaView offscreen; None on success, else why it failed."""
    pvpython = pvpython or shutil.which("pvpython")
    if pvpython is None:
        return "pvpython not found"
    # Debian's ParaView renders through X even offscreen: without a display, a virtual one
    virtual_x = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24"] \
        if not os.environ.get("DISPLAY") and shutil.which("xvfb-run") else []
    try:
        with atomic_path(path) as tmp:  # renamed into place only when pvpython wrote it
            os.unlink(tmp)
            command = virtual_x + [pvpython, "--force-offscreen-rendering", SCRIPT, frame_path, tmp, title,
                                   str(DAMAGED_SHOWN)]
            for _ in range(2):  # a second try: a virtual X server that starts slowly aborts pvpython now and then
                result = subprocess.run(command, capture_output=True, text=True, timeout=PVPYTHON_TIMEOUT)
                if result.returncode == 0 and os.path.isfile(tmp):
                    break
            if result.returncode != 0 or not os.path.isfile(tmp):
                tail = (result.stderr or result.stdout).strip().splitlines()[-3:]
                raise _RenderFailed(f"pvpython failed (exit {result.returncode}): " + " | ".join(tail))
    except _RenderFailed as error:
        return str(error)
    except (OSError, subprocess.TimeoutExpired) as error:
        return f"pvpython failed: {error}"
    return None


def render_damage_3d(frame_path: str, frame, case: CaseSettings, path: str, *, time: float) -> str:
    """damage_3d.png with pvpython when it is there and works, else with matplotlib."""
    t_factor, t_unit = si_scale([time], "s")
    why = render_with_pvpython(frame_path, path, short_title(case, f"damage at t = {time * t_factor:.4g} {t_unit}"))
    if why is None:
        return f"damage_3d.png (ParaView, offscreen): nodes with damage > {DAMAGED_SHOWN:g} of the last frame"
    if why != "pvpython not found":
        print(f"postprocess: note: {why}; drawing damage_3d.png with matplotlib", file=sys.stderr)
    return plot_damage_3d_matplotlib(frame.points, frame.damage, case, path, time=time)
