"""What every figure shares: the Agg backend (no display), the style, the atomic PNG save, and the
helpers that make a figure readable in a report: quantities in SI units with a prefix chosen so the
numbers read 1…1000 (time in µs or ms, displacement in µm or mm), tick labels without an offset
text ("1e-5" or "+1.23e-3" in a corner), short titles, and a legend inside the axes that covers no data.
"""
from __future__ import annotations

import math
import sys

import matplotlib

matplotlib.use("Agg")  # before pyplot: never look for a display

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import ScalarFormatter  # noqa: E402

from common.atomic import atomic_path  # noqa: E402

from .casefile import DEFAULT_DPI  # noqa: E402

# The figures' layout resolution: sizes are in points and marker sizes are computed at this
# resolution (maps.py); the PNG is written at the case's figures.dpi, which scales the pixels only.
DPI = 150
# SI prefixes from large to small: the first whose factor is ≤ the largest value is used.
PREFIXES = ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p"))
# A title longer than this wraps or crowds the axes: figure titles say what, not where from.
TITLE_MAX = 60


def new_figure(rows: int = 1, cols: int = 1, *, size=(7.0, 5.0), **kwargs):
    """A figure of `rows` × `cols` axes, drawn on Agg."""
    return plt.subplots(rows, cols, figsize=size, dpi=DPI, squeeze=False, **kwargs)


def save_figure(fig, path: str, dpi: int = DEFAULT_DPI):
    """Write the figure as PNG at `dpi` (figures.dpi) under a temporary name, rename it into place,
    and free it. The page is cropped to what is drawn (bbox "tight"), which keeps every size in points."""
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png", dpi=dpi, bbox_inches="tight", pad_inches=0.15)
    finally:
        plt.close(fig)


def si_scale(values, unit: str) -> tuple[float, str]:
    """(factor, prefixed unit) so that values × factor have their largest magnitude in [1, 1000):
    si_scale([0, 4.3e-5], "s") == (1e6, "µs"). All-zero or non-finite values keep the unit."""
    values = np.abs(np.asarray(values, dtype=np.float64))
    values = values[np.isfinite(values)]
    largest = float(values.max()) if values.size else 0.0
    if largest == 0.0:
        return 1.0, unit
    for factor, prefix in PREFIXES:
        # 1 − 1e-9: 0.001 s read from a file as 0.000999999… is still 1 ms
        if largest >= factor * (1.0 - 1e-9):
            return 1.0 / factor, prefix + unit
    return 1.0 / PREFIXES[-1][0], PREFIXES[-1][1] + unit


def time_axis(t) -> tuple[np.ndarray, str]:
    """Time in the unit that fits the run (s, ms, µs, ns): (scaled times, axis label)."""
    factor, unit = si_scale(t, "s")
    return np.asarray(t, dtype=np.float64) * factor, f"time t [{unit}]"


def plain_ticks(ax):
    """No offset text and no ×10ⁿ multiplier on the linear axes of `ax` (the values are scaled
    to their SI prefix instead); log axes keep their own formatter."""
    for axis in (ax.xaxis, ax.yaxis):
        formatter = axis.get_major_formatter()
        if isinstance(formatter, ScalarFormatter):
            formatter.set_useOffset(False)
            formatter.set_scientific(False)


def _data_vertices(ax) -> np.ndarray:
    """Display coordinates of every vertex of the lines and scatters drawn in `ax`."""
    parts = []
    for line in ax.get_lines():
        xy = np.asarray(line.get_xydata(), dtype=np.float64)
        if xy.size:
            parts.append(ax.transData.transform(xy[np.all(np.isfinite(xy), axis=1)]))
    for collection in ax.collections:
        offsets = np.asarray(collection.get_offsets(), dtype=np.float64)
        if offsets.ndim == 2 and len(offsets):
            parts.append(ax.transData.transform(offsets))
    return np.concatenate(parts) if parts else np.zeros((0, 2))


def legend_covers(ax) -> int:
    """How many data vertices of `ax` lie under its legend's box (0: the legend covers no data)."""
    legend = ax.get_legend()
    if legend is None:
        return 0
    box = legend.get_window_extent(ax.figure.canvas.get_renderer())
    xy = _data_vertices(ax)
    inside = (xy[:, 0] >= box.x0) & (xy[:, 0] <= box.x1) & (xy[:, 1] >= box.y0) & (xy[:, 1] <= box.y1)
    return int(np.count_nonzero(inside))


def place_legend(ax, **kwargs):
    """A legend inside the axes that covers no data: matplotlib's 'best' place first; if every place
    covers some curve, room is made above the data (the y range grows by a quarter at a time) and
    the legend goes into it, in two columns when it has many entries."""
    legend = ax.legend(loc="best", **kwargs)
    ax.figure.canvas.draw()
    if legend_covers(ax) == 0:
        return legend
    entries = len(ax.get_legend_handles_labels()[1])
    for grow in range(1, 9):
        bottom, top = ax.get_ylim()
        if ax.get_yscale() == "log":
            ax.set_ylim(bottom, top * 10.0 ** (0.25 * math.log10(max(top / bottom, 10.0))))
        else:
            ax.set_ylim(bottom, top + 0.25 * (top - bottom))
        legend = ax.legend(loc="upper center", ncol=2 if entries > 3 else 1, **kwargs)
        ax.figure.canvas.draw()
        if legend_covers(ax) == 0:
            break
    return legend


def short_title(case, what: str) -> str:
    """"<case>: <what>", the case's name only (its one-line description is for the README, not for
    every title); without the name when that would pass TITLE_MAX characters."""
    name = getattr(case, "name", None) or getattr(case, "heading", "")
    text = f"{name}: {what}" if name else what
    return text if len(text) <= TITLE_MAX else what


def say(what: str):
    """One line to stderr per figure drawn: post-processing says what it draws (issue 16)."""
    print(f"postprocess: {what}", file=sys.stderr, flush=True)
