"""figures.times: null draws a run that breaks at its crack's growth (issue 39, item 3): evenly
spread times missed plate_with_hole's cracks, which grow in 0.92-0.96 ms of a 1.1 ms run."""
import numpy as np

from postprocess.selection import default_times, event_times


def test_the_maps_of_a_run_that_breaks_follow_the_broken_bond_count():
    frames = np.arange(0, 56) * 2e-5                       # plate_with_hole's 56 frames to 1.1 ms
    history_t = np.linspace(0, 1.1e-3, 8001)
    # no bond before 0.92 ms, then 8434 broken by 0.96 ms, a few more to the end
    broken = np.interp(history_t, [0, 0.92e-3, 0.96e-3, 1.1e-3], [0, 0, 8000, 8434]).round()
    chosen = event_times(frames, history_t, broken)
    # 10 %, 50 %, 90 % of 8434 broken are reached at 0.9242, 0.9411 and 0.9580 ms: the first frames
    # at or after them are 0.94, 0.96 and 0.96 ms (frames 47, 48, 48); then the last frame and the
    # one before the crack's start (0.92 ms) make four maps.
    assert chosen == [frames[46], frames[47], frames[48], frames[55]]
    # evenly spread times put no map inside the growth
    assert not any(0.92e-3 < t < 0.96e-3 for t in default_times(frames))


def test_a_run_with_no_broken_bond_keeps_the_evenly_spread_times():
    frames = np.linspace(0, 1e-2, 51)
    assert event_times(frames, frames, np.zeros(51)) is None
