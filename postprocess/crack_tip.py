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
  the specimen, side by side: each reaches farther across the line through them than along it),
  each crack gets its own two tracks, "crack k, ±axis end", from its own first damaged nodes along
  its own longest axis in the x–y plane, among its own nodes only (separate: no crack node of one
  within CLUSTER_REACH node spacings of the other; specks of damage, below SPECK of the largest
  crack's nodes or MIN_CRACK_NODES, are no cracks and are followed by no track). A track whose tip
  never leaves its origin is dropped.

Used by the normal output (postprocess/crack_plot.py: crack_path.png and crack_tips.csv) and by
`python -m validation branching`.
"""
from __future__ import annotations

import dataclasses

import numpy as np

DAMAGED = 0.3    # damage above which a node belongs to the crack (validation/branching.py, C7)
SPEED_LAG = 2    # frames over which the tip speed is measured (branching: 2 × 1 µs, as C7)
# Separate cracks (plan_tracks): crack nodes closer than CLUSTER_REACH node spacings belong to one
# crack; a group smaller than SPECK × the largest, or than MIN_CRACK_NODES, is no crack of its own.
CLUSTER_REACH = 2.5
SPECK = 0.1
MIN_CRACK_NODES = 5
# Growth the frames do not follow (not_resolved): at least this share of an end's length, and at
# least MIN_JUMP node spacings, between two frames.
UNRESOLVED = 0.5
MIN_JUMP = 2.0


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


def _ahead(x: np.ndarray, track: Track) -> tuple[np.ndarray, np.ndarray]:
    """Each node's distance along the track's direction from its origin, and whether it may hold
    the tip: ahead of the origin, on the track's side, among its members."""
    relative = x - track.origin
    ahead = relative @ track.direction
    allowed = ahead > 0.0
    if track.side is not None:
        allowed &= relative @ track.side >= 0.0
    if track.members is not None:
        allowed &= track.members
    return ahead, allowed


def tip_positions(x, crack_masks, track: Track) -> np.ndarray:
    """(frames, 3) tip of `track` in each frame: among the crack nodes (crack_masks[i], a bool per
    node) ahead of the origin ((x − origin)·direction > 0) and on its side, the one farthest along
    the direction (the first such node on a tie); when there is none, the origin (a notch tip, from
    which the crack starts) or NaN (a crack without a notch has no tip before it appears: its
    first tip lies on the body's edge, and a step from the origin there is no speed)."""
    x = _points3(x)
    ahead, allowed = _ahead(x, track)
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


def end_lengths(x, crack_masks, track: Track) -> np.ndarray:
    """(frames,) the length of `track`'s end of the crack in each frame [m]: along its direction,
    from the first to the farthest of its crack nodes (ahead of the origin, on its side, among its
    members) — from the notch tip for a notch's track; 0 while it has none. Not the tip's distance
    from the origin: a crack without a notch starts where its first nodes broke (the edge of a
    hole, not the hole's centre where the origin of both its ends lies)."""
    ahead, allowed = _ahead(_points3(x), track)
    lengths = np.zeros(len(crack_masks))
    for i, crack in enumerate(crack_masks):
        along = ahead[crack & allowed]
        if len(along):
            lengths[i] = along.max() - (0.0 if track.rests_at_origin else along.min())
    return lengths


def not_resolved(times, x, crack_masks, track: Track, spacing: float) -> tuple[float, float, float] | None:
    """(growth [m], t_a, t_b) when `track`'s end grew at least UNRESOLVED × its largest length, and at
    least MIN_JUMP node spacings, between two frames t_a < t_b: the frames do not follow its run (a
    crack that runs in µs, as a mixed run's between load steps, against frames 0.1 ms apart), and
    growth / (t_b − t_a) is only a lower bound of its mean speed. None when the frames follow it.
    Frames at one time (series.py keeps them) count as one, the last."""
    t = np.asarray(times, dtype=np.float64)
    keep = np.append(t[1:] > t[:-1], True)  # the last of frames at one time
    lengths = end_lengths(x, crack_masks, track)[keep]
    t = t[keep]
    if len(t) < 2 or not lengths.max() > 0.0:
        return None
    growth = np.diff(lengths)
    k = int(np.argmax(growth))
    if growth[k] >= UNRESOLVED * lengths.max() and growth[k] >= MIN_JUMP * spacing:
        return float(growth[k]), float(t[k]), float(t[k + 1])
    return None


def typical_spacing(points) -> float:
    """The median distance from a node to its nearest other node (the lattice's spacing); 0 for fewer
    than two nodes."""
    from scipy.spatial import cKDTree

    points = _points3(points)
    if len(points) < 2:
        return 0.0
    nearest, _ = cKDTree(points).query(points, k=2)
    return float(np.median(nearest[:, 1]))


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


def _xy_axis(points: np.ndarray) -> np.ndarray:
    """The longest axis of a cloud of points in the x–y plane (z 0: a 3D crack through the thickness
    runs in the plane, whatever its depth; its largest component positive); x for a single point."""
    flat = points[:, :2]
    if len(flat) < 2:
        return np.array([1.0, 0.0, 0.0])
    _, _, vt = np.linalg.svd(flat - flat.mean(axis=0), full_matrices=False)
    axis = np.array([vt[0][0], vt[0][1], 0.0])
    return _unit(axis * np.sign(axis[np.argmax(np.abs(axis))]))


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
    links = tree.query_pairs(CLUSTER_REACH * typical_spacing(points), output_type="ndarray")
    graph = coo_matrix((np.ones(len(links)), (links[:, 0], links[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    groups = sorted((np.flatnonzero(label == k) for k in np.unique(label)), key=len, reverse=True)
    return [g for g in groups if len(g) >= max(SPECK * len(groups[0]), min(MIN_CRACK_NODES, len(groups[0])))]


def _on_one_line(groups: list[np.ndarray], points: np.ndarray) -> bool:
    """Whether separate cracks lie on one line, so that one pair of tracks from where they started
    follows both (the two cracks from a hole's edges), rather than side by side (cases/traction's
    two cracks across the specimen): side by side when every crack reaches farther across the line
    through their centroids (in the x–y plane) than along it. A crack's own axis would not do: the
    damage of a quasi-statically grown crack is 6 mm wide for 10 mm long (traction quasi_static)."""
    centroids = np.array([points[g].mean(axis=0) for g in groups])
    line = _xy_axis(centroids)
    across = np.array([-line[1], line[0], 0.0])
    for g in groups:
        p = points[g]
        along, side = p @ line, p @ across
        if np.ptp(side) <= np.ptp(along):
            return True
    return False


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
        side_by_side = len(groups) > 1 and not _on_one_line(groups, x[grown_nodes])
        if side_by_side:
            # cracks side by side: numbered along the line through them (below, once the tracks
            # that never left their origin are dropped)
            centroids = np.array([x[grown_nodes[g]].mean(axis=0) for g in groups])
            order = np.argsort(centroids @ _xy_axis(centroids))
            parts = [grown_nodes[groups[i]] for i in order]
        else:
            # one crack, or cracks on one line: one pair of tracks over them (specks left out)
            parts = [grown_nodes[np.concatenate(groups)]] if groups else []
        for nodes in parts:
            members = np.zeros(len(x), dtype=bool)
            members[nodes] = True
            first = next(i for i, crack in enumerate(crack_masks) if (crack & members).any())
            origin = x[crack_masks[first] & members].mean(axis=0)
            direction = _xy_axis(x[nodes]) if side_by_side else _principal_axis(x[nodes])
            axis = "xyz"[int(np.argmax(np.abs(direction)))]
            tracks += [Track(f"+{axis} end", origin, direction, rests_at_origin=False, members=members),
                       Track(f"−{axis} end", origin, -direction, rests_at_origin=False, members=members)]

    def moved(track):
        tips = tip_positions(x, crack_masks, track)
        found = np.all(np.isfinite(tips), axis=1)
        return bool(np.any(np.linalg.norm(tips[found] - track.origin, axis=1) > 0.0))

    kept = [t for t in tracks if moved(t)]
    if len(cracks) or len({id(t.members) for t in kept}) < 2:
        return kept
    # cracks side by side, numbered 1, 2, … among those still followed
    number = {}
    for t in kept:
        number.setdefault(id(t.members), len(number) + 1)
    return [dataclasses.replace(t, name=f"crack {number[id(t.members)]}, {t.name}") for t in kept]
