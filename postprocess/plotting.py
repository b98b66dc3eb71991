"""What every figure shares: the Agg backend (no display), the style, and the atomic PNG save."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")  # before pyplot: never look for a display

import matplotlib.pyplot as plt  # noqa: E402

from pipeline.atomic import atomic_path  # noqa: E402

DPI = 150


def new_figure(rows: int = 1, cols: int = 1, *, size=(7.0, 5.0), **kwargs):
    """A figure of `rows` × `cols` axes, drawn on Agg."""
    return plt.subplots(rows, cols, figsize=size, dpi=DPI, squeeze=False, **kwargs)


def save_figure(fig, path: str):
    """Write the figure as PNG under a temporary name, rename it into place, and free it.
    The page is cropped to what is drawn (bbox "tight"), which keeps every size in points."""
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png", dpi=DPI, bbox_inches="tight", pad_inches=0.15)
    finally:
        plt.close(fig)
