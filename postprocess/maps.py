"""damage_<i>.png and displacement_<i>.png: one frame's damage or displacement component on the nodes.

2D cases: a scatter in the x–y plane (reference positions), one square marker per node, sized to
the node spacing, equal aspect; the damage map colours damage and, while broken bonds are few
(BOND_SHARE), draws them as light half-transparent hairlines (black lines hid the damage colours
along the crack). Coordinates, displacement and time are drawn in the SI prefix that fits (mm, µm, µs).
3D cases: two panels, a 3D scatter of the whole body (its surface is what shows) and the slice of
nodes nearest to the mid-plane z = (z_min + z_max)/2 drawn like a 2D map, so that cracks inside the
body are visible.
"""
from __future__ import annotations

import numpy as np
from matplotlib.collections import LineCollection
from mpl_toolkits.axes_grid1 import make_axes_locatable

from .casefile import AXES, CaseSettings
from .plotting import DPI, new_figure, plain_ticks, plt, save_figure, short_title, si_scale
from .series import Frame

# Broken bonds: a light grey hairline, half transparent, over the nodes (issue 16: black at 0.3 pt
# buried the damage colours under the lines where the crack is). Only while they are few (at most
# BOND_SHARE per node drawn): then a single broken bond, too little to colour its nodes much, still
# shows. Once a crack has run, every node along it has a dozen broken bonds; their lines would
# cover the damage colours, which show the crack by themselves (gmsh/damage_final.pos has them all).
BOND_COLOUR, BOND_WIDTH, BOND_ALPHA = "0.85", 0.15, 0.5
BOND_SHARE = 0.1
MAX_3D_POINTS = 60000  # a denser 3D scatter is subsampled (every k-th node): matplotlib draws each marker


def node_spacing(points: np.ndarray, dimension: int, grid_spacing: float | None) -> float:
    """dx [m] from case.json, else the spacing of a uniform cloud filling the bounding box."""
    if grid_spacing:
        return float(grid_spacing)
    extent = np.ptp(points[:, :dimension], axis=0)
    extent = extent[extent > 0]
    if extent.size == 0:
        return 1.0
    n = max(len(points), 1)
    return float(np.prod(extent) / n) ** (1.0 / extent.size)


def displacement_range(frames: list[Frame], component: int) -> tuple[float, float]:
    """A colour range symmetric about 0, shared by the displacement maps so they compare at a glance."""
    largest = 0.0
    for frame in frames:
        values = np.abs(frame.displacement[:, component])
        values = values[np.isfinite(values)]  # a run that blew up still gets a usable scale
        if values.size:
            largest = max(largest, float(values.max()))
    if largest == 0.0:
        largest = 1.0
    return -largest, largest


def _draw_plane(ax, xy: np.ndarray, values, segments, spacing, cmap, vmin, vmax):
    """Nodes as squares (sized later by _size_markers) and, while few, broken bonds as hairlines."""
    scatter = ax.scatter(xy[:, 0], xy[:, 1], c=values, cmap=cmap, vmin=vmin, vmax=vmax, s=1.0,
                         marker="s", linewidths=0)
    if segments is not None and 0 < len(segments) <= BOND_SHARE * len(xy):
        ax.add_collection(LineCollection(segments, colors=BOND_COLOUR, linewidths=BOND_WIDTH, alpha=BOND_ALPHA))
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    ax.set_xlim(lo[0] - spacing, hi[0] + spacing)
    ax.set_ylim(lo[1] - spacing, hi[1] + spacing)
    ax.set_aspect("equal")
    return scatter


def _size_markers(ax, scatter, spacing):
    """Marker side = node spacing on screen: computed once the axes have their final size."""
    ax.apply_aspect()
    (x0, _), (x1, _) = ax.transData.transform([(0.0, 0.0), (spacing, 0.0)])
    side_points = abs(x1 - x0) * 72.0 / DPI
    scatter.set_sizes([max(side_points, 0.3) ** 2])


def plot_map(frame: Frame, case: CaseSettings, path: str, *, quantity: str, time: float,
             index: int, requested: float | None = None, vrange=None):
    """Draw `quantity` ("damage" or "displacement") of one frame; `vrange` fixes the colour range."""
    points = frame.points
    length, length_unit = si_scale(points, "m")
    if quantity == "damage":
        values, cmap = frame.damage, "viridis"
        vmin, vmax = vrange or (0.0, 1.0)
        label = "damage φ [–]"
        bonds = frame.broken_bonds
    elif quantity == "displacement":
        vmin, vmax = vrange or displacement_range([frame], case.component)
        scale, unit = si_scale([vmin, vmax], "m")
        values, cmap = frame.displacement[:, case.component] * scale, "RdBu_r"
        vmin, vmax = vmin * scale, vmax * scale
        label = f"displacement u_{AXES[case.component]} [{unit}]"
        bonds = np.zeros((0, 2), dtype=np.int64)
    else:
        raise ValueError(f"unknown quantity {quantity!r}")
    spacing = node_spacing(points, case.dimension, case.grid_spacing) * length
    points = points * length
    t_scale, t_unit = si_scale([time or requested or 0.0], "s")
    what = "damage" if quantity == "damage" else f"u_{AXES[case.component]}"
    subtitle = short_title(case, f"{what} at t = {time * t_scale:.4g} {t_unit}")
    note = f"frame {index}"
    if len(bonds) > BOND_SHARE * len(points):
        note += f", {len(bonds)} broken bonds (not drawn)"
    if requested is not None and f"{requested:.4g}" != f"{time:.4g}":
        note += f", the nearest to t = {requested * t_scale:.4g} {t_unit}"

    if case.dimension == 2:
        lo, hi = points[:, :2].min(axis=0), points[:, :2].max(axis=0)
        ratio = (hi[1] - lo[1] + 2 * spacing) / (hi[0] - lo[0] + 2 * spacing)
        fig, axes = new_figure(size=(7.0, float(np.clip(1.6 + 5.4 * ratio, 3.5, 10.0))))
        ax = axes[0, 0]
        segments = points[bonds][:, :, :2] if len(bonds) else None
        scatter = _draw_plane(ax, points[:, :2], values, segments, spacing, cmap, vmin, vmax)
        ax.set_xlabel(f"x [{length_unit}]")
        ax.set_ylabel(f"y [{length_unit}]")
        ax.set_title(f"{subtitle}\n{note}", fontsize="medium")
        plain_ticks(ax)
        # a colour bar as tall as the equal-aspect axes
        cax = make_axes_locatable(ax).append_axes("right", size="4%", pad=0.12)
        fig.colorbar(scatter, cax=cax, label=label)
        plain_ticks(cax)
        fig.tight_layout()
        _size_markers(ax, scatter, spacing)
    else:
        fig = plt.figure(figsize=(12.0, 5.5), dpi=DPI)
        grid = fig.add_gridspec(1, 2, left=0.03, right=0.86, wspace=0.38)
        ax3 = fig.add_subplot(grid[0, 0], projection="3d")
        stride = max(1, int(np.ceil(len(points) / MAX_3D_POINTS)))
        shown = slice(None, None, stride)
        extent = np.maximum(np.ptp(points, axis=0), spacing)
        ax3.set_box_aspect(tuple(extent))  # a tuple: matplotlib normalises an array in place
        # the drawn 3D box spans about half of its panel's width: a node's diameter in points
        panel_points = ax3.get_position().width * fig.get_figwidth() * 72.0
        side = 0.5 * panel_points * spacing / float(extent.max())
        scatter3 = ax3.scatter(points[shown, 0], points[shown, 1], points[shown, 2], c=values[shown],
                               cmap=cmap, vmin=vmin, vmax=vmax, s=max(side, 0.5) ** 2, marker="o",
                               linewidths=0, depthshade=False)
        ax3.tick_params(labelsize="x-small")
        ax3.set_xlabel(f"x [{length_unit}]")
        ax3.set_ylabel(f"y [{length_unit}]")
        ax3.set_zlabel(f"z [{length_unit}]")
        ax3.set_title("whole body" + (f" (every {stride}th node)" if stride > 1 else ""), fontsize="small")

        ax = fig.add_subplot(grid[0, 1])
        z = points[:, 2]
        mid = 0.5 * (z.min() + z.max())
        layer = z[np.argmin(np.abs(z - mid))]
        in_slice = np.abs(z - layer) <= 0.5 * spacing
        kept = np.flatnonzero(in_slice)
        segments = None
        if len(bonds):
            both = in_slice[bonds[:, 0]] & in_slice[bonds[:, 1]]
            segments = points[bonds[both]][:, :, :2]
        scatter = _draw_plane(ax, points[kept, :2], values[kept], segments, spacing, cmap, vmin, vmax)
        ax.set_xlabel(f"x [{length_unit}]")
        ax.set_ylabel(f"y [{length_unit}]")
        ax.set_title(f"nodes of the layer nearest the mid-plane: z = {layer:.4g} {length_unit}", fontsize="small")
        plain_ticks(ax)
        fig.suptitle(f"{subtitle}\n{note}", fontsize="medium")
        cax = fig.add_axes([0.89, 0.2, 0.015, 0.6])
        fig.colorbar(scatter3, cax=cax, label=label)
        plain_ticks(cax)
        _size_markers(ax, scatter, spacing)
    save_figure(fig, path, case.dpi)
