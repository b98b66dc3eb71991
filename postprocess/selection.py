"""Which frames the damage and displacement maps show (the nearest to each requested time), and
which node the probe follows (the nearest to the centre)."""
from __future__ import annotations

from typing import Sequence

import numpy as np

DEFAULT_MAP_COUNT = 4


def default_times(frame_times: Sequence[float], count: int = DEFAULT_MAP_COUNT) -> list[float]:
    """Times for `figures.times: null`: `count` times evenly spread over the run, ending at its last
    frame, t0 + k (t_end − t0) / count for k = 1..count (the initial, undeformed state is left out)."""
    first, last = float(frame_times[0]), float(frame_times[-1])
    return [first + k * (last - first) / count for k in range(1, count + 1)]


def select_frames(frame_times: Sequence[float], requested: Sequence[float]) -> list[int]:
    """Index of the frame nearest in time to each requested time, one per request, in request order.

    `frame_times` must be sorted (read_series sorts them). A tie between two frames goes to the
    earlier one; a time outside the run gets the first or the last frame.
    """
    times = np.asarray(frame_times, dtype=np.float64)
    if times.size == 0:
        raise ValueError("no frames to choose from")
    if np.any(np.diff(times) < 0):
        raise ValueError("frame times are not sorted")
    chosen = []
    for t in requested:
        right = int(np.searchsorted(times, t, side="left"))  # first frame at or after t
        if right == 0:
            chosen.append(0)
        elif right == times.size:
            chosen.append(times.size - 1)
        else:
            left = right - 1
            # earliest frame among equal times on the left side
            left = int(np.searchsorted(times, times[left], side="left"))
            chosen.append(left if t - times[left] <= times[right] - t else right)
    return chosen


def centre_node(points: np.ndarray) -> int:
    """The probe node: nearest to the centre of the bounding box of the reference positions
    (the lowest index among equally near nodes)."""
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    return int(np.argmin(np.sum((points - centre) ** 2, axis=1)))
