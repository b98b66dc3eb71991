"""The crack-tip tracker (postprocess/crack_tip.py) on synthetic damage fields whose tip path and
speed are known, crack_path.png checked as the other report figures are, crack_tips.csv's numbers,
and `python -m postprocess` drawing them only when a crack grew; validation/branching.py uses the
same tracker (no second copy)."""
import csv
import json

import numpy as np
import pytest
from matplotlib import pyplot as plt

import synthetic_output as synth
from postprocess import cli, crack_plot, crack_tip
from postprocess.casefile import CaseSettings
from test_post_report_figures import check_readable

DX = 1.0e-3                 # m
FRAME = 2.0e-6              # s between frames
SPEED = 500.0               # m/s: the tip advances one node spacing per frame
NX, NY = 41, 21             # nodes along x and y
NOTCH_Y = 10.5 * DX         # the notch line lies between node rows 10 and 11
NOTCH_TIP = 10 * DX         # the notch runs from x = 0 to here
START = 3                   # frames with the notch only; then the tip runs


def grid():
    x, y = np.meshgrid(DX * np.arange(NX), DX * np.arange(NY), indexing="xy")
    return np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])


def known_tip_x(k):
    """x of the last crack node in frame k: the notch tip's column until START, then one column per frame."""
    return NOTCH_TIP + DX * max(0, k - START)


def notch_damage(points, frames=12):
    """Damage 0.5 on the two node rows beside the notch line up to known_tip_x(k); a few decoys: a
    node ahead of the tip with damage 0.25 (below DAMAGED) and an undamaged lattice elsewhere."""
    x, y = points[:, 0], points[:, 1]
    beside = np.isclose(y, 10 * DX) | np.isclose(y, 11 * DX)
    fields = []
    for k in range(frames):
        damage = np.where(beside & (x <= known_tip_x(k) + 1e-12), 0.5, 0.0)
        damage[np.isclose(x, known_tip_x(k) + 3 * DX) & np.isclose(y, 11 * DX)] = 0.25
        fields.append(damage)
    return np.arange(frames) * FRAME, fields


def test_tracker_follows_a_known_tip_from_a_notch():
    points = grid()
    times, fields = notch_damage(points)
    masks = [d > crack_tip.DAMAGED for d in fields]
    tracks = crack_tip.plan_tracks(points, masks, [([0.0, NOTCH_Y, 0.0], [NOTCH_TIP, NOTCH_Y, 0.0])])
    assert [t.name for t in tracks] == ["above the notch line", "below the notch line"]
    assert np.allclose(tracks[0].origin, [NOTCH_TIP, NOTCH_Y, 0.0]) and np.allclose(tracks[0].direction, [1, 0, 0])
    above = crack_tip.tip_positions(points, masks, tracks[0])
    below = crack_tip.tip_positions(points, masks, tracks[1])
    for k in range(len(times)):
        if k <= START:   # nothing beyond the notch tip yet: the tip stays at the notch tip
            assert np.allclose(above[k], tracks[0].origin)
        else:
            assert np.allclose(above[k], [known_tip_x(k), 11 * DX, 0.0])
            assert np.allclose(below[k], [known_tip_x(k), 10 * DX, 0.0])
    mid, speed = crack_tip.tip_speeds(times, below)
    assert np.allclose(mid, times[1:-1])           # two-frame windows centred on the frames
    running = mid > (START + 1) * FRAME             # both window ends past the notch tip
    assert np.allclose(speed[running], SPEED, rtol=1e-12)
    assert np.allclose(speed[mid < START * FRAME], 0.0)


def test_tracker_without_a_notch_follows_both_ends_at_their_speeds():
    """A crack that starts at the centre and runs up at 500 m/s and down at 250 m/s (a tip that
    moves every other frame): two tracks, +y and −y, from the centre, at those mean speeds."""
    points = grid()
    x, y = points[:, 0], points[:, 1]
    column = np.isclose(x, 20 * DX)
    frames = 9
    fields = []
    for k in range(frames):
        up, down = 10 + k, 10 - k // 2
        fields.append(np.where(column & (y >= down * DX - 1e-12) & (y <= up * DX + 1e-12) & (k >= 1), 0.6, 0.0))
    times = np.arange(frames) * FRAME
    masks = [d > crack_tip.DAMAGED for d in fields]
    tracks = crack_tip.plan_tracks(points, masks)
    assert [t.name for t in tracks] == ["+y end", "−y end"]
    assert np.allclose(tracks[0].origin, [20 * DX, 10.5 * DX, 0.0])  # the centroid of the first damaged nodes
    up = crack_tip.tip_positions(points, masks, tracks[0])
    down = crack_tip.tip_positions(points, masks, tracks[1])
    assert np.isnan(up[0]).all() and np.isnan(down[0]).all()   # no tip before the crack appears
    assert np.allclose(up[1:, 1], DX * (10 + np.arange(1, frames)))
    assert np.allclose(down[2:, 1], DX * (10 - np.arange(2, frames) // 2))
    _, speed_up = crack_tip.tip_speeds(times[1:], up[1:])
    _, speed_down = crack_tip.tip_speeds(times[2:], down[2:])
    assert np.allclose(speed_up, SPEED) and np.allclose(speed_down, SPEED / 2)


def test_two_cracks_side_by_side_get_two_tracks_each_and_cracks_on_one_line_one_pair():
    """Two cracks across the body at x = 10 and 30 dx, growing up and down from y = 10 dx one node
    per frame (cases/traction's two cracks): each its own +y and −y end, its tips its own nodes
    only, at 500 m/s. Two cracks on one line (from the edges of a hole at y = 7..13 dx, running
    away from it): one pair of tracks from where they started, as before."""
    points = grid()
    x, y = points[:, 0], points[:, 1]
    frames = 8
    times = np.arange(frames) * FRAME

    def masks_of(columns, grows):
        out = []
        for k in range(frames):
            mask = np.zeros(len(points), bool)
            if k >= 1:
                for c in columns:
                    mask |= np.isclose(x, c * DX) & grows(k)
            out.append(mask)
        return out

    side_by_side = masks_of((10, 30), lambda k: (y >= (10 - k) * DX - 1e-12) & (y <= (10 + k) * DX + 1e-12))
    tracks = crack_tip.plan_tracks(points, side_by_side)
    # the second crack starting 2 frames later: its origin is its own first nodes'
    later = [m & ~(np.isclose(x, 30 * DX) & (k < 3)) for k, m in enumerate(side_by_side)]
    late = crack_tip.plan_tracks(points, later)
    assert np.allclose(late[2].origin, [30 * DX, 10 * DX, 0.0]) and np.allclose(late[0].origin, [10 * DX, 10 * DX, 0.0])
    assert [t.name for t in tracks] == ["crack 1, +y end", "crack 1, −y end", "crack 2, +y end", "crack 2, −y end"]
    for track, column, sign in zip(tracks, (10, 10, 30, 30), (1, -1, 1, -1)):
        tips = crack_tip.tip_positions(points, side_by_side, track)
        assert np.allclose(tips[1:, 0], column * DX)                               # its own crack's nodes
        assert np.allclose(tips[2:, 1], (10 + sign * np.arange(2, frames)) * DX)    # its end, one node per frame
        _, speed = crack_tip.tip_speeds(times[2:], tips[2:])
        assert np.allclose(speed, SPEED)
    # wide damage, as a quasi-statically grown crack's (5 nodes wide, 15 long at the end): still two
    wide = masks_of((8, 9, 10, 11, 12, 28, 29, 30, 31, 32),
                    lambda k: (y >= (10 - k) * DX - 1e-12) & (y <= (10 + k) * DX + 1e-12))
    assert [t.name for t in crack_tip.plan_tracks(points, wide)] == [t.name for t in tracks]
    # a speck of damage far from both (one node) is no crack of its own
    speck = [m.copy() for m in side_by_side]
    speck[-1][np.flatnonzero(np.isclose(x, 20 * DX) & np.isclose(y, 0.0))] = True
    assert [t.name for t in crack_tip.plan_tracks(points, speck)] == [t.name for t in tracks]
    # on one line: above and below a hole at the centre column
    on_a_line = masks_of((20,), lambda k: ((y >= 13 * DX - 1e-12) & (y <= (13 + k) * DX + 1e-12))
                         | ((y <= 7 * DX + 1e-12) & (y >= (7 - k) * DX - 1e-12)))
    assert [t.name for t in crack_tip.plan_tracks(points, on_a_line)] == ["+y end", "−y end"]


def test_no_tracks_when_nothing_grew_beyond_the_notch():
    points = grid()
    times, fields = notch_damage(points)
    masks = [fields[0] > crack_tip.DAMAGED] * 5
    assert crack_tip.plan_tracks(points, masks, [([0.0, NOTCH_Y], [NOTCH_TIP, NOTCH_Y])]) == []
    assert crack_tip.plan_tracks(points, [np.zeros(len(points), bool)] * 3) == []


def test_validation_branching_uses_the_shared_tracker():
    """validation/branching.py on a stand-in run: the speed the known field has, and no copy of the
    tracker of its own."""
    from validation import branching
    import inspect
    points = grid()
    times, fields = notch_damage(points)

    class Frame:
        def __init__(self, damage):
            self.damage = damage

    class FakeRun:
        case = {"cracks": [{"from": [0.0, NOTCH_Y, 0.0], "to": [NOTCH_TIP, NOTCH_Y, 0.0]}]}
        x = points
        series = list(zip(times, fields))

        def __init__(self):
            self.times = times

        def frame(self, i):
            return Frame(fields[i])

    mid, speed = branching.tip_speeds(FakeRun())
    assert np.allclose(speed[mid > (START + 1) * FRAME], SPEED)
    assert branching.DAMAGED is crack_tip.DAMAGED
    assert "argmax" not in inspect.getsource(branching.tip_history)


def fracture_case():
    return CaseSettings(name="branching", dimension=2, title="Crack branching in soda-lime glass (docs/theory.md C7)",
                        cracks=[([0.0, NOTCH_Y, 0.0], [NOTCH_TIP, NOTCH_Y, 0.0])])


@pytest.fixture
def drawn(monkeypatch):
    """crack_plot's figure, drawn and kept instead of saved: drawn["fig"] after plot_crack_path."""
    kept = {}

    def spy(fig, path, dpi):
        fig.canvas.draw()
        kept["fig"] = fig

    monkeypatch.setattr(crack_plot, "save_figure", spy)
    return kept


def test_crack_path_figure_is_readable_and_draws_the_known_speed(drawn, tmp_path):
    kept = drawn
    points = grid()
    times, fields = notch_damage(points)
    masks = [d > crack_tip.DAMAGED for d in fields]
    case = fracture_case()
    tracks = crack_tip.plan_tracks(points, masks, case.cracks)
    said = crack_plot.plot_crack_path(times, points, masks, tracks, case, str(tmp_path / "crack_path.png"))
    fig = kept["fig"]
    try:
        check_readable(fig)
        ax_path, ax_speed = fig.axes
        assert ax_path.get_xlabel() == "x [mm]" and ax_speed.get_xlabel() == "time t [µs]"
        assert ax_path.get_title() == "branching: crack path"
        # the speed curves, in µs: 500 m/s once the window is past the notch tip
        for line in ax_speed.get_lines():
            t_us, v = line.get_xydata().T
            assert np.allclose(v[t_us > (START + 1) * FRAME * 1e6], SPEED)
        # the path: the last tip in mm
        path_lines = [line for line in ax_path.get_lines() if line.get_label().startswith("tip")]
        assert len(path_lines) == 2
        assert np.allclose(path_lines[0].get_xydata()[-1], [known_tip_x(len(times) - 1) * 1e3, 11.0])
        # the peak: the first step off the notch tip, which lies between two node rows
        peak = np.hypot(2 * DX, 0.5 * DX) / (2 * FRAME)
        assert f"peak speed {peak:.4g} m/s at {(START + 1) * FRAME * 1e6:.4g} µs" in said
    finally:
        plt.close(fig)


def test_a_crack_that_grew_between_two_frames_is_reported_as_not_resolved(drawn, tmp_path):
    """A crack without a notch that appears 9 nodes long between frames 4 and 5 and grows no more
    (a mixed run's crack runs in µs between frames 0.1 ms apart): no peak speed (the frames would
    say 0 m/s), but the growth, the frame interval and the lower bound of the mean speed."""
    kept = drawn
    points = grid()
    x, y = points[:, 0], points[:, 1]
    crack = np.isclose(x, 20 * DX) & (y >= 6 * DX - 1e-12) & (y <= 14 * DX + 1e-12)
    times = np.arange(9) * FRAME
    masks = [crack if k >= 5 else np.zeros(len(points), bool) for k in range(len(times))]
    tracks = crack_tip.plan_tracks(points, masks)
    assert [t.name for t in tracks] == ["+y end", "−y end"]
    # each end: its nodes ahead of the centre, y = 11 … 14 dx, 3 dx from first to last
    assert crack_tip.not_resolved(times, points, masks, tracks[0], DX) == pytest.approx((3 * DX, 4 * FRAME, 5 * FRAME))
    case = CaseSettings(name="snap", dimension=2, title="snap")
    said = crack_plot.plot_crack_path(times, points, masks, tracks, case, str(tmp_path / "crack_path.png"))
    try:
        check_readable(kept["fig"])
        assert "m/s at" not in said  # no peak speed
        bound = 3 * DX / FRAME  # 1500 m/s
        assert (f"not resolved by the frames (+y end: 3 mm between {4 * FRAME * 1e6:.4g} and {5 * FRAME * 1e6:.4g} µs, "
                f"at least {bound:.0f} m/s on average") in said
        assert "−y end: 3 mm" in said
        assert said.endswith("; frames more often (output.every_time) would follow the crack's run")
        texts = [t.get_text() for t in kept["fig"].axes[1].texts]
        assert texts == [f"speed not resolved by the frames:\n+y end: 3 mm in one frame interval, ≥ {bound:.0f} m/s\n"
                         f"−y end: 3 mm in one frame interval, ≥ {bound:.0f} m/s"]
        assert kept["fig"].axes[1].get_lines() == []  # no speed curve that would show the run as a stop
        # crack_tips.csv leaves their speeds empty (the frames' 0 m/s would contradict the line)
        rows = crack_plot.tip_table(times, points, masks, tracks)
        assert all(r["speed"] is None for r in rows)
    finally:
        plt.close(kept["fig"])


def test_growth_the_frames_follow_is_not_flagged_and_a_notch_crack_that_jumps_is():
    """Not resolved only when an end grew at least half its length, and 2 node spacings, between two
    frames: the cracks from a hole's edges (y = 13 dx up, 7 dx down) growing a node per frame from
    frame 1 are followed (their first nodes are at the hole's edge, not at its centre where both
    ends' origin lies), at 500 m/s; a notch crack that runs 8 dx between two frames is not; frames
    at one time count once."""
    points = grid()
    x, y = points[:, 0], points[:, 1]
    frames = 8
    times = np.arange(frames) * FRAME
    column = np.isclose(x, 20 * DX)
    masks = [column & (((y >= 13 * DX - 1e-12) & (y <= (12 + k) * DX + 1e-12))
                       | ((y <= 7 * DX + 1e-12) & (y >= (8 - k) * DX - 1e-12))) for k in range(frames)]
    tracks = crack_tip.plan_tracks(points, masks)
    assert [t.name for t in tracks] == ["+y end", "−y end"]
    for track in tracks:
        assert crack_tip.not_resolved(times, points, masks, track, DX) is None
    rows = crack_plot.tip_table(times, points, masks, tracks)
    assert any(r["speed"] == pytest.approx(SPEED) for r in rows)
    # the notch crack jumping from the notch tip to 8 dx beyond it between frames 3 and 4
    _, fields = notch_damage(points)
    jumped = [fields[min(k, 3)] if k < 4 else fields[-1] for k in range(len(fields))]
    masks = [d > crack_tip.DAMAGED for d in jumped]
    notch_times = np.arange(len(fields)) * FRAME
    below = crack_tip.plan_tracks(points, masks, [([0.0, NOTCH_Y], [NOTCH_TIP, NOTCH_Y])])[1]
    growth, t_a, t_b = crack_tip.not_resolved(notch_times, points, masks, below, DX)
    assert (t_a, t_b) == pytest.approx((3 * FRAME, 4 * FRAME))
    assert growth == pytest.approx(known_tip_x(len(fields) - 1) - NOTCH_TIP)
    # a frame repeated at the same time: the same verdict, no division by a zero interval
    again = np.insert(notch_times, 4, notch_times[4])
    masks_again = masks[:4] + [masks[4]] + masks[4:]
    assert crack_tip.not_resolved(again, points, masks_again, below, DX) == pytest.approx((growth, t_a, t_b))


def write_fracture_run(out, *, grow=True):
    """A run in out/ with the notch_damage frames (or the notch only), a breakable block, the notch."""
    out.mkdir(parents=True)
    (out / "frames").mkdir()
    points = grid()
    times, fields = notch_damage(points)
    entries = []
    for k, (t, damage) in enumerate(zip(times, fields if grow else [fields[0]] * len(fields))):
        name = f"frames/frame_{k:06d}.vtu"
        synth.write_vtu(out / name, points, {"displacement": np.zeros((len(points), 3)), "damage": damage},
                        {"TIME": float(t), "step": np.int64(k)}, np.zeros((0, 2), np.int64))
        entries.append((float(t), name))
    synth.write_pvd(out / "frames.pvd", entries)
    synth.write_history(out / "history.csv", synth.history_values(rows=len(times), end=float(times[-1])))
    case = {"format_version": 1, "case": "notched", "dimension": 2, "grid_spacing": DX,
            "blocks": [{"id": 1, "name": "plate", "model": "pmb", "fracture_energy": 3.0}],
            "cracks": [{"from": [0.0, NOTCH_Y, 0.0], "to": [NOTCH_TIP, NOTCH_Y, 0.0]}],
            "figures": {"times": None, "displacement_component": 0}, "output": {"gmsh": "none"}}
    (out / "case.json").write_text(json.dumps(case))
    return times


def test_postprocess_writes_crack_path_and_tip_speeds(tmp_path):
    out = tmp_path / "notched"
    times = write_fracture_run(out)
    written = cli.run(str(out), log=lambda *_: None)
    assert str(out / "figures" / "crack_path.png") in written
    synth.png_size(out / "figures" / "crack_path.png")
    with open(out / "crack_tips.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert list(rows[0]) == list(crack_plot.CSV_COLUMNS)
    below = [r for r in rows if r["tip"] == "below the notch line"]
    assert len(below) == len(times)
    assert below[0]["speed"] == "" and below[-1]["speed"] == ""
    for k, row in enumerate(below):
        assert float(row["x"]) == pytest.approx(known_tip_x(k))
        assert float(row["y"]) == pytest.approx(10 * DX if k > START else NOTCH_Y)   # the notch tip until it runs
        assert float(row["extension"]) == pytest.approx(np.hypot(known_tip_x(k) - NOTCH_TIP, 0.5 * DX)
                                                        if k > START else 0.0)
        if START + 1 < k < len(times) - 1:
            assert float(row["speed"]) == pytest.approx(SPEED, rel=1e-6)


def test_postprocess_draws_no_crack_path_when_no_crack_grew(tmp_path, capsys):
    out = tmp_path / "notched"
    write_fracture_run(out, grow=False)
    (out / "figures").mkdir()
    (out / "figures" / "crack_path.png").write_bytes(b"stale")   # from an earlier run
    cli.run(str(out), log=lambda *_: None)
    assert not (out / "figures" / "crack_path.png").exists() and not (out / "crack_tips.csv").exists()
    assert "crack_path.png: none, no crack grew" in capsys.readouterr().err


def test_no_crack_outputs_for_an_unbreakable_run(run2d, capsys):
    cli.run(str(run2d.out), log=lambda *_: None)
    assert not (run2d.out / "figures" / "crack_path.png").exists() and not (run2d.out / "crack_tips.csv").exists()
    assert "crack_path" not in capsys.readouterr().err
