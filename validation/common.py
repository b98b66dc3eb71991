"""What every check shares: the Check row, readers of a finished run, lattice helpers."""
from __future__ import annotations

import dataclasses
import json
import os

import numpy as np

from postprocess.history import read_history
from postprocess.series import read_frame, read_series


@dataclasses.dataclass
class Check:
    case: str
    quantity: str
    expected: str      # the target with its tolerance, as text for the report
    got: float | str   # the measured value
    passed: bool
    note: str = ""

    def row(self) -> str:
        got = f"{self.got:.4g}" if isinstance(self.got, (float, int, np.floating)) else str(self.got)
        return f"| {self.case} | {self.quantity} | {self.expected} | {got} | {'yes' if self.passed else '**NO**'} |"


class Run:
    """A finished run in out_dir: case.json, nodes.vtu, history.csv and the frames (read lazily)."""

    def __init__(self, out_dir: str):
        self.out_dir = out_dir
        with open(os.path.join(out_dir, "case.json"), encoding="utf-8") as stream:
            self.case = json.load(stream)
        self.history = read_history(os.path.join(out_dir, "history.csv"))
        self.series = read_series(os.path.join(out_dir, "frames.pvd"))
        self.times = np.array([t for t, _ in self.series])
        self._frames: dict[int, object] = {}
        first = self.frame(0)
        self.x = first.points
        self.dx = float(self.case["grid_spacing"])
        self.horizon = float(self.case["horizon"])

    def frame(self, index: int):
        if index < 0:
            index += len(self.series)
        if index not in self._frames:
            self._frames[index] = read_frame(self.series[index][1])
        return self._frames[index]

    def node_set(self, name: str) -> np.ndarray:
        import meshio
        nodes = meshio.read(os.path.join(self.out_dir, "nodes.vtu"))
        return nodes.point_data[f"set_{name}"].astype(bool)

    def broken_count(self, index: int) -> int:
        return len(self.frame(index).broken_bonds)

    def block(self, name: str) -> dict:
        return next(b for b in self.case["blocks"] if b["name"] == name)


def slope(x: np.ndarray, u: np.ndarray) -> float:
    """Least-squares slope du/dx."""
    return float(np.polyfit(x, u, 1)[0])


def mean_strain_xx(x: np.ndarray, u: np.ndarray, x0: float, half_width: float) -> float:
    """Mean ∂u_x/∂x over the whole cross-section near x = x0: the slope of the straight line
    fitted to u_x(x) over every node with |x − x0| ≤ half_width, plus the row-by-row offset
    removed (each row its own intercept), so a bending or a lateral variation does not bias it."""
    sel = np.abs(x[:, 0] - x0) <= half_width
    rows = np.round(x[sel, 1] / 1e-9).astype(np.int64)
    xs, us = x[sel, 0].copy(), u[sel, 0].copy()
    for r in np.unique(rows):  # remove each row's mean: a common slope with per-row intercepts
        m = rows == r
        xs[m] -= xs[m].mean()
        us[m] -= us[m].mean()
    return float(np.sum(xs * us) / np.sum(xs * xs))


def first_frame_with_breakage(run: Run, already: int = 0) -> int | None:
    """Index of the first frame with more broken bonds than `already` (pre-cracks), or None."""
    for i in range(len(run.series)):
        if run.broken_count(i) > already:
            return i
    return None


def angle_from_axis(vectors: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Angle in degrees between each vector and the line along `axis` (0..90: direction-free)."""
    axis = axis / np.linalg.norm(axis)
    cos = np.abs(vectors @ axis) / np.linalg.norm(vectors, axis=1)
    return np.degrees(np.arccos(np.clip(cos, 0.0, 1.0)))


def principal_direction(points: np.ndarray) -> np.ndarray:
    """Unit vector along which a 2D point cloud is longest (largest principal axis)."""
    centred = points[:, :2] - points[:, :2].mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    return vt[0]
