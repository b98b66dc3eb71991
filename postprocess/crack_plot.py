"""crack_path.png and crack_tips.csv: the path of each crack tip and its speed against time, for a
run in which a crack grew (the tips from postprocess/crack_tip.py).

crack_path.png, left: the final crack (its nodes, φ > DAMAGED, light grey) seen in the x–y plane
(3D: from above) with each tip's path over it, a dot per frame; right: each tip's speed against
time, over SPEED_LAG frames. crack_tips.csv: one row per frame and tip, columns time [s], tip (the
track's name), x, y, z [m], extension (distance of the tip from its origin [m]), speed [m/s] over
the frames i − 1 … i + 1 (empty at the first and last frame); empty cells where a crack without a
notch has no tip yet (pipeline/formats.md §4). A tip that grew at least half its length, and 2
node spacings, between two frames (crack_tip.not_resolved) is reported as not resolved, with the lower bound of its mean speed
that the frames give, instead of a peak speed the frames cannot show (its speed cells in
crack_tips.csv are left empty, its curve is not drawn).
"""
from __future__ import annotations

import csv
import io

import numpy as np

from common.atomic import write_atomically

from .casefile import CaseSettings
from .crack_tip import DAMAGED, SPEED_LAG, Track, not_resolved, tip_positions, tip_speeds, typical_spacing
from .plotting import new_figure, place_legend, plain_ticks, save_figure, short_title, si_scale, time_axis

CSV_COLUMNS = ("time", "tip", "x", "y", "z", "extension", "speed")


def unresolved_growth(times, x, crack_masks, tracks: list[Track]) -> dict[str, tuple[float, float, float]]:
    """The tracks whose growth the frames do not follow (crack_tip.not_resolved), by name."""
    final = np.asarray(x)[crack_masks[-1]] if len(crack_masks) else np.zeros((0, 3))
    spacing = typical_spacing(final)
    out = {}
    for track in tracks:
        found = not_resolved(times, x, crack_masks, track, spacing)
        if found is not None:
            out[track.name] = found
    return out


def tip_table(times, x, crack_masks, tracks: list[Track], unresolved: dict | None = None) -> list[dict]:
    """Rows of crack_tips.csv: per frame and track, the tip, its extension and its speed over the
    SPEED_LAG frames centred on it (None where the window leaves the run, and for a track whose
    growth the frames do not follow: `unresolved`, unresolved_growth's, computed here if not given)."""
    rows = []
    half = SPEED_LAG // 2
    if unresolved is None:
        unresolved = unresolved_growth(times, x, crack_masks, tracks)
    for track in tracks:
        tips = tip_positions(x, crack_masks, track)
        _, speed = tip_speeds(times, tips)
        if track.name in unresolved:
            speed = np.full_like(speed, np.nan)
        for i, t in enumerate(times):
            k = i - half  # the window [i − half, i + half] is speed[k]
            found = bool(np.all(np.isfinite(tips[i])))
            v = float(speed[k]) if 0 <= k < len(speed) else np.nan
            rows.append({"time": float(t), "tip": track.name, "x": tips[i, 0], "y": tips[i, 1], "z": tips[i, 2],
                         "extension": float(np.linalg.norm(tips[i] - track.origin)) if found else np.nan,
                         "speed": v if np.isfinite(v) else None})
    return rows


def write_tip_csv(path: str, rows: list[dict]):
    """crack_tips.csv, written under a temporary name and renamed into place."""
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for row in rows:
        writer.writerow([f"{row['time']:.9g}", row["tip"]] +
                        ["" if np.isnan(row[k]) else f"{row[k]:.9g}" for k in ("x", "y", "z", "extension")] +
                        ["" if row["speed"] is None else f"{row['speed']:.6g}"])
    write_atomically(path, text.getvalue())


def _speed(v: float) -> str:
    """A speed for the log: whole m/s from 100 m/s on (not 1e+04), 3 digits below."""
    return f"{v:.0f}" if v >= 100.0 else f"{v:.3g}"


def plot_crack_path(times, x, crack_masks, tracks: list[Track], case: CaseSettings, path: str,
                    not_followed: dict | None = None) -> str:
    """crack_path.png (see the module docstring); returns the line post-processing says.
    `not_followed`: unresolved_growth's verdict, computed here if not given."""
    x = np.asarray(x, dtype=np.float64)
    final = x[crack_masks[-1]]
    length, length_unit = si_scale(x[:, :2], "m")
    t_factor, t_unit = si_scale(times, "s")  # the speed's mid-times in the unit of the run's times
    t_scaled, t_label = time_axis(times)
    fig, axes = new_figure(1, 2, size=(12.0, 4.8), gridspec_kw={"width_ratios": [1.3, 1.0]})
    ax_path, ax_speed = axes[0]
    ax_path.scatter(final[:, 0] * length, final[:, 1] * length, s=4.0, color="0.65", marker="s", linewidths=0,
                    label=f"crack nodes at the end (φ > {DAMAGED:g})")
    lo, hi = x[:, :2].min(axis=0) * length, x[:, :2].max(axis=0) * length
    ax_path.set_xlim(lo[0], hi[0])
    ax_path.set_ylim(lo[1], hi[1])
    ax_path.set_aspect("equal")
    peaks, unresolved = [], []
    if not_followed is None:
        not_followed = unresolved_growth(times, x, crack_masks, tracks)
    for number, track in enumerate(tracks):
        colour = f"C{number}"
        tips = tip_positions(x, crack_masks, track)
        ax_path.plot(tips[:, 0] * length, tips[:, 1] * length, "-", color=colour, lw=1.0, marker=".", ms=3,
                     label=f"tip, {track.name}")
        mid, speed = tip_speeds(times, tips)
        if track.name in not_followed:
            # Most of this end grew between two frames: a speed from the frames would be a
            # fraction of the real one (0 once it has stopped), so say what the frames do show.
            jump, t_a, t_b = not_followed[track.name]
            bound = _speed(jump / (t_b - t_a))
            unresolved.append(f"{track.name}: {jump * length:.3g} {length_unit} in one frame interval, ≥ {bound} m/s")
            peaks.append(f"not resolved by the frames ({track.name}: {jump * length:.3g} {length_unit} between "
                         f"{t_a * t_factor:.4g} and {t_b * t_factor:.4g} {t_unit}, at least {bound} m/s on average)")
        elif np.isfinite(speed).any():
            ax_speed.plot(mid * t_factor, speed, "-", color=colour,
                          marker=".", ms=3, label=track.name)
            k = int(np.nanargmax(speed))
            peaks.append(f"{speed[k]:.4g} m/s at {mid[k] * t_factor:.4g} {t_unit} ({track.name})")
    ax_path.set_xlabel(f"x [{length_unit}]")
    ax_path.set_ylabel(f"y [{length_unit}]")
    ax_path.set_title(short_title(case, "crack path" + (" (seen from +z)" if case.dimension == 3 else "")))
    plain_ticks(ax_path)
    place_legend(ax_path, fontsize="small")
    ax_speed.set_xlim(t_scaled[0], t_scaled[-1])
    ax_speed.set_xlabel(t_label)
    ax_speed.set_ylabel("tip speed [m/s]")
    ax_speed.set_title(f"tip speed: its advance from frame k−{SPEED_LAG // 2} to k+{SPEED_LAG // 2}")
    ax_speed.set_ylim(bottom=0.0)
    ax_speed.grid(alpha=0.3)
    plain_ticks(ax_speed)
    if unresolved:
        # (their speed from the frames is not drawn: it would show the run as a stop)
        ax_speed.text(0.02, 0.97, "speed not resolved by the frames:\n" + "\n".join(unresolved),
                      transform=ax_speed.transAxes, fontsize="small", ha="left", va="top",
                      bbox={"facecolor": "white", "edgecolor": "0.7", "alpha": 0.9})
    if tracks and ax_speed.get_lines():
        place_legend(ax_speed, fontsize="small")
    fig.tight_layout()
    save_figure(fig, path, case.dpi)
    return (f"crack_path.png and crack_tips.csv: {len(tracks)} crack tip(s) over {len(times)} frames; "
            f"peak speed {'; '.join(peaks) if peaks else 'none'}" +
            ("; frames more often (output.every_time) would follow the crack's run" if unresolved else ""))
