"""Which frames the damage and displacement maps show (the nearest to each requested time), and
which node the probe follows (the nearest to the centre)."""
from __future__ import annotations

import os
from typing import Sequence

import numpy as np

DEFAULT_MAP_COUNT = 4


def default_times(frame_times: Sequence[float], count: int = DEFAULT_MAP_COUNT) -> list[float]:
    """Times for `figures.times: null`: `count` times evenly spread over the run, ending at its last
    frame, t0 + k (t_end − t0) / count for k = 1..count (the initial, undeformed state is left out)."""
    first, last = float(frame_times[0]), float(frame_times[-1])
    return [first + k * (last - first) / count for k in range(1, count + 1)]


# Fractions of the final broken-bond count at which the maps of a run that breaks are drawn, then
# its last frame: the crack's start, middle and end of growth. Evenly spread times missed the event
# (issue 39: plate_with_hole's cracks grow in 0.92–0.96 ms of a 1.1 ms run, between two maps).
EVENT_FRACTIONS = (0.1, 0.5, 0.9)


def event_times(frame_times: Sequence[float], history_times: Sequence[float],
                broken_bonds: Sequence[float], count: int = DEFAULT_MAP_COUNT) -> list[float] | None:
    """Times for `figures.times: null` when bonds break, `count` distinct frames (fewer only if the
    run has fewer), chosen in this order: the first frame at or after each moment the broken-bond
    count (history.csv) reaches a fraction EVENT_FRACTIONS of its final value, the last frame, the
    frame before the crack's start, default_times', then the latest frames left. None when no bond
    breaks."""
    broken = np.asarray(broken_bonds, dtype=np.float64)
    if broken.size == 0 or broken[-1] <= 0:
        return None
    frames = np.asarray(frame_times, dtype=np.float64)
    candidates: list[int] = []
    for fraction in EVENT_FRACTIONS:
        row = int(np.argmax(broken >= fraction * broken[-1]))
        candidates.append(min(int(np.searchsorted(frames, history_times[row], side="left")), frames.size - 1))
    candidates += [frames.size - 1, max(candidates[0] - 1, 0)]
    candidates += select_frames(frames, default_times(frames, count))
    candidates += range(frames.size - 1, -1, -1)        # any frame left, latest first
    chosen: list[int] = []
    for index in candidates:
        if index not in chosen and len(chosen) < count:
            chosen.append(index)
    return [float(frames[index]) for index in sorted(chosen)]


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


def nearest_node(points: np.ndarray, point) -> int:
    """The node nearest to `point` (x, y, z) [m], the lowest index among equally near ones."""
    return int(np.argmin(np.sum((points - np.asarray(point, dtype=np.float64)) ** 2, axis=1)))


def probe_nodes(points: np.ndarray, probe, nodes_vtu: str | None = None) -> tuple[np.ndarray, str]:
    """The nodes whose displacement probe.png follows (figures.probe) and a short description:
    None → the node nearest the centre of the box; [x, y, z] → the node nearest that point; a
    node-set name → every node of the set (from the set_<name> array of nodes.vtu, formats.md §1),
    whose mean displacement is drawn."""
    from .errors import PostprocessError

    if probe is None:
        node = centre_node(points)
        return np.array([node]), f"node {node}, nearest the centre"
    if not isinstance(probe, str):
        node = nearest_node(points, probe)
        return np.array([node]), f"node {node}, nearest the probe point"
    from meshio import vtu

    if nodes_vtu is None or not os.path.isfile(nodes_vtu):
        raise PostprocessError(f"figures.probe: '{probe}' is a node set, read from the node file "
                               f"{nodes_vtu}, which does not exist; preprocess the case again")
    data = vtu.read(nodes_vtu).point_data
    array = data.get(f"set_{probe}")
    if array is None:
        sets = sorted(name[4:] for name in data if name.startswith("set_"))
        raise PostprocessError(f"figures.probe: no node set '{probe}' in {nodes_vtu}; "
                               f"its sets are: {', '.join(sets) or 'none'}")
    members = np.flatnonzero(np.asarray(array).reshape(-1) != 0)
    if len(array) != len(points) or len(members) == 0:
        raise PostprocessError(f"figures.probe: node set '{probe}' of {nodes_vtu} has "
                               f"{len(members)} of {len(array)} nodes; the frames have {len(points)}")
    return members, f"mean of the {len(members)} nodes of '{probe}'"
