"""A finished run's results as numpy arrays: history.csv by column, frames by index or time."""
from __future__ import annotations

import json
import os

import numpy as np

from postprocess.history import read_history
from postprocess.series import Frame, read_frame, read_series


def open_run(out_dir: str) -> "Run":
    """The results in `out_dir` (a `make` output folder or one written by Case.run)."""
    return Run(out_dir)


class Run:
    """Reads lazily: history.csv on first use, a frame when asked for."""

    def __init__(self, out_dir: str):
        self.out_dir = os.path.abspath(out_dir)
        if not os.path.isfile(os.path.join(self.out_dir, "frames.pvd")):
            raise FileNotFoundError(f"{self.out_dir}/frames.pvd: no run here (run the case first)")
        self._history = None
        self._series = read_series(os.path.join(self.out_dir, "frames.pvd"))

    @property
    def history(self) -> dict[str, np.ndarray]:
        """history.csv: column name → array (int64 for counts, float64 for the rest)."""
        if self._history is None:
            self._history = read_history(os.path.join(self.out_dir, "history.csv"))
        return self._history

    @property
    def case(self) -> dict:
        """The resolved case.json (pipeline/formats.md §3)."""
        with open(os.path.join(self.out_dir, "case.json"), encoding="utf-8") as stream:
            return json.load(stream)

    @property
    def times(self) -> np.ndarray:
        """The frames' times [s]."""
        return np.array([t for t, _ in self._series])

    def __len__(self) -> int:
        return len(self._series)

    def frame(self, index: int) -> Frame:
        """Frame `index` (negative counts from the end): .points, .displacement, .damage,
        .point_data (every array), .broken_bonds (node pairs), .time."""
        return read_frame(self._series[index][1])

    def frame_at(self, time: float) -> Frame:
        """The frame nearest in time to `time` [s]."""
        return self.frame(int(np.argmin(np.abs(self.times - time))))

    def frames(self):
        """Every frame, in time order, one at a time."""
        for _, path in self._series:
            yield read_frame(path)

    def __repr__(self) -> str:
        return f"peridyn.Run({self.out_dir!r}: {len(self)} frames)"
