"""Crack-tip tracking: where the tip of a crack is in each frame, and how fast it runs.

A node belongs to the crack when its damage φ (the share of its bonds broken, thesis eq. 2.9)
exceeds DAMAGED. A crack grows from an origin along a direction; a *track* follows it: in every
frame its tip is the crack node farthest along the direction among the nodes ahead of the origin
(and on one side of the crack line when a side is given), else the origin itself. The tip speed is
|Δ tip| / Δt over `lag` frames: a lattice crack advances in jumps of one node spacing, so a speed
between neighbouring frames only is noisy (Bobaru & Zhang 2015 measure it the same way, over a few
µs).

How the tracks are chosen (plan_tracks):
- a pre-crack (case.json `cracks`): from the end of the notch where new damage appears, along the
  notch, two tracks: the crack nodes on either side of the notch line (a crack that branches is
  followed on each branch; validation/branching.py uses the upper one);
- no pre-crack: from the centroid of the nodes first damaged, along the principal direction of the
  final crack (the longest axis of its nodes), two tracks: forward and backward (the two cracks
  from the edge of a hole, or the two ends of a crack that starts inside). When the final crack
  nodes fall into separate cracks that do not lie on one line (cases/traction's two cracks across
  the specimen, side by side), each crack gets its own two tracks, "crack k, ±axis end", from its
  own first damaged nodes along its own longest axis, among its own nodes only (separate: no crack
  node of one within CLUSTER_REACH node spacings of the other; small specks of damage, below
  SPECK of the largest crack's nodes, are not cracks). A track whose tip never leaves its origin is
  dropped.

Used by the normal output (postprocess/crack_plot.py: crack_path.png and crack_tips.csv) and by
`python -m validation branching`.
"""
from __future__ import annotations

import dataclasses

import numpy as np

DAMAGED = 0.3    # damage above which a node belongs to the crack (validation/branching.py, C7)
CLUSTER_REACH = 2.5  # crack nodes closer than this many node spacings belong to one crack
SPECK = 0.1          # a group of crack nodes smaller than this share of the largest is no crack of its own
COLLINEAR = 0.87     # cos 30°: cracks whose axes lie within 30° of the line through them are one line
SPEED_LAG = 2    # frames over which the tip speed is measured (branching: 2 × 1 µs, as C7)


@dataclasses.dataclass
class Track:
    name: str                     # legend and CSV label, e.g. "upper", "+y"
    origin: np.ndarray            # (3,) [m]: where the crack starts (a notch tip)
    direction: np.ndarray         # (3,) unit: along which the tip runs
    side: np.ndarray | None = None  # (3,) unit: only nodes with (x − origin)·side ≥ 0 (one branch)
    rests_at_origin: bool = True  # no crack node ahead: the tip is the origin (a notch tip), else NaN
    members: np.ndarray | None = None  # bool per node: the tip is among these nodes only (one of several cracks)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def _points3(x) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    return x if x.shape[1] == 3 else np.hstack([x, np.zeros((len(x), 3 - x.shape[1]))])


def tip_positions(x, crack_masks, track: Track) -> np.ndarray:
    """(frames, 3) tip of `track` in each frame: among the crack nodes (crack_masks[i], a bool per
    node) ahead of the origin ((x − origin)·direction > 0) and on its side, the one farthest along
    the direction (the first such node on a tie); when there is none, the origin (a notch tip, from
    which the crack starts) or NaN (a crack without a notch has no tip before it appears: its
    first tip lies on the body's edge, and a step from the origin there is no speed)."""
    x = _points3(x)
    relative = x - track.origin
    ahead = relative @ track.direction
    allowed = ahead > 0.0
    if track.side is not None:
        allowed &= relative @ track.side >= 0.0
    if track.members is not None:
        allowed &= track.members
    tips = np.empty((len(crack_masks), 3))
    for i, crack in enumerate(crack_masks):
        candidates = np.flatnonzero(crack & allowed)
        if len(candidates):
            tips[i] = x[candidates[np.argmax(ahead[candidates])]]
        else:
            tips[i] = track.origin if track.rests_at_origin else np.nan
    return tips


def tip_speeds(times, tips, lag: int = SPEED_LAG) -> tuple[np.ndarray, np.ndarray]:
    """(window mid-times [s], speeds [m/s]): |tip(t_{i+lag}) − tip(t_i)| / (t_{i+lag} − t_i).
    Fewer than lag + 1 frames: empty arrays."""
    t = np.asarray(times, dtype=np.float64)
    tips = np.asarray(tips, dtype=np.float64)
    if len(t) <= lag:
        return np.zeros(0), np.zeros(0)
    speed = np.linalg.norm(tips[lag:] - tips[:-lag], axis=1) / (t[lag:] - t[:-lag])
    return 0.5 * (t[lag:] + t[:-lag]), speed


def largest_jump(times, tips, track: Track) -> tuple[float, int]:
    """(growth [m], k): the largest growth of the tip's distance from its origin between frames
    k and k + 1 (a tip that first appears counts from the origin). When it is at least
    UNRESOLVED × the largest distance the crack reaches, the frames do not follow the crack's run:
    it grew most of its length between two frames (a crack that runs in a few µs, as a mixed run's
    explicit phase between load steps, against frames every 0.1 ms), and jump / Δt is only a lower
    bound of its mean speed. (0, 0) with fewer than two frames."""
    tips = np.asarray(tips, dtype=np.float64)
    if len(tips) < 2:
        return 0.0, 0
    found = np.all(np.isfinite(tips), axis=1)
    extension = np.where(found, np.linalg.norm(np.where(found[:, None], tips, 0.0) - track.origin, axis=1), 0.0)
    growth = np.diff(extension)
    k = int(np.argmax(growth))
    return float(growth[k]), k


UNRESOLVED = 0.5  # a crack that grew this share of its length between two frames is not followed


def _xy_normal(direction: np.ndarray) -> np.ndarray:
    """The direction turned by +90° about z: the side "above" a crack line in the xy plane."""
    return _unit([-direction[1], direction[0], 0.0])


def _principal_axis(points: np.ndarray) -> np.ndarray:
    """The longest axis of a cloud of points (unit; its largest component positive, for readable
    names); x for a single point."""
    if len(points) < 2:
        return np.array([1.0, 0.0, 0.0])
    _, _, vt = np.linalg.svd(points - points.mean(axis=0), full_matrices=False)
    direction = vt[0]
    return _unit(direction * np.sign(direction[np.argmax(np.abs(direction))]))


def separate_cracks(points: np.ndarray) -> list[np.ndarray]:
    """Index arrays of the separate cracks among crack nodes `points` (n, 3): nodes closer than
    CLUSTER_REACH × their typical spacing (the median distance to the nearest other crack node) are
    linked, a crack is a linked group (connected components of that graph); groups smaller than
    SPECK × the largest are left out. Largest first."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    n = len(points)
    if n < 2:
        return [np.arange(n)] if n else []
    tree = cKDTree(points)
    nearest, _ = tree.query(points, k=2)
    reach = CLUSTER_REACH * float(np.median(nearest[:, 1]))
    links = tree.query_pairs(reach, output_type="ndarray")
    graph = coo_matrix((np.ones(len(links)), (links[:, 0], links[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    groups = sorted((np.flatnonzero(label == k) for k in np.unique(label)), key=len, reverse=True)
    return [g for g in groups if len(g) >= SPECK * len(groups[0])]


def _on_one_line(groups: list[np.ndarray], points: np.ndarray) -> bool:
    """Whether separate cracks lie on one line: each one's longest axis within 30° of the line
    through their centroids (the two cracks from a hole's edges), so that one pair of tracks from
    where they started follows both."""
    centroids = np.array([points[g].mean(axis=0) for g in groups])
    line = _principal_axis(centroids)
    return all(abs(float(_principal_axis(points[g]) @ line)) >= COLLINEAR for g in groups)


def plan_tracks(x, crack_masks, cracks=()) -> list[Track]:
    """The tracks of a run (see the module docstring): [] when no crack grew beyond the pre-cracks.
    `cracks`: the pre-cracks as (from, to) points [m]; x the reference positions."""
    x = _points3(x)
    if not len(crack_masks):
        return []
    grown = crack_masks[-1] & ~crack_masks[0]
    if not grown.any():
        return []
    tracks = []
    if len(cracks):
        for number, (start, end) in enumerate(cracks):
            start, end = _points3(np.atleast_2d(start))[0], _points3(np.atleast_2d(end))[0]
            # the notch's tip is the end nearer to the new damage
            near = lambda p: float(np.min(np.linalg.norm(x[grown] - p, axis=1)))  # noqa: E731
            if near(start) < near(end):
                start, end = end, start
            direction = _unit(end - start)
            normal = _xy_normal(direction)
            label = f"crack {number + 1} " if len(cracks) > 1 else ""
            tracks += [Track(f"{label}above the notch line", end, direction, normal),
                       Track(f"{label}below the notch line", end, direction, -normal)]
    else:
        grown_nodes = np.flatnonzero(grown)
        groups = separate_cracks(x[grown_nodes])
        if len(groups) > 1 and not _on_one_line(groups, x[grown_nodes]):
            # cracks side by side: numbered along the line through them
            centroids = np.array([x[grown_nodes[g]].mean(axis=0) for g in groups])
            order = np.argsort(centroids @ _principal_axis(centroids))
            parts = [(f"crack {k + 1}, ", grown_nodes[groups[i]]) for k, i in enumerate(order)]
        else:
            parts = [("", grown_nodes)]
        for label, nodes in parts:
            members = None
            if label:
                members = np.zeros(len(x), dtype=bool)
                members[nodes] = True
            inside = members if members is not None else np.ones(len(x), dtype=bool)
            first = next(i for i, crack in enumerate(crack_masks) if (crack & ~crack_masks[0] & inside).any())
            origin = x[crack_masks[first] & ~crack_masks[0] & inside].mean(axis=0)
            direction = _principal_axis(x[nodes])
            axis = "xyz"[int(np.argmax(np.abs(direction)))]
            tracks += [Track(f"{label}+{axis} end", origin, direction, rests_at_origin=False, members=members),
                       Track(f"{label}−{axis} end", origin, -direction, rests_at_origin=False, members=members)]

    def moved(track):
        tips = tip_positions(x, crack_masks, track)
        found = np.all(np.isfinite(tips), axis=1)
        return bool(np.any(np.linalg.norm(tips[found] - track.origin, axis=1) > 0.0))

    return [t for t in tracks if moved(t)]
