"""Which frames the maps show and which node the probe follows."""
import numpy as np
import pytest

import synthetic_output as synth
from postprocess.selection import centre_node, default_times, select_frames

TIMES = [0.0, 1.0e-4, 2.0e-4, 3.0e-4, 4.0e-4, 5.0e-4]


def test_each_requested_time_gets_the_nearest_frame_in_request_order():
    assert select_frames(TIMES, [0.0, 1.0e-4, 5.0e-4]) == [0, 1, 5]
    assert select_frames(TIMES, [1.4e-4, 1.6e-4, 4.9e-4, 0.2e-4]) == [1, 2, 5, 0]
    assert select_frames(TIMES, [3.0e-4, 3.0e-4]) == [3, 3]


def test_a_tie_goes_to_the_earlier_frame_and_times_outside_the_run_to_its_ends():
    times = [0.0, 1.0, 2.0, 4.0]
    assert select_frames(times, [0.5, 1.5, 3.0]) == [0, 1, 2]
    assert select_frames(times, [-1.0, 10.0]) == [0, 3]
    assert select_frames([0.0, 1.0, 1.0, 2.0], [1.0, 1.2]) == [1, 1]  # equal times: the first listed


def test_selection_agrees_with_brute_force_on_irregular_times():
    rng = np.random.default_rng(7)
    times = np.sort(rng.uniform(0.0, 1.0, 40))
    requested = rng.uniform(-0.1, 1.1, 200)
    chosen = select_frames(times, requested)
    for t, i in zip(requested, chosen):
        assert abs(times[i] - t) == np.min(np.abs(times - t))


def test_unsorted_or_empty_frame_times_are_refused():
    with pytest.raises(ValueError):
        select_frames([0.0, 2.0, 1.0], [1.0])
    with pytest.raises(ValueError):
        select_frames([], [1.0])


def test_default_is_four_times_spread_over_the_run_ending_at_the_last_frame():
    assert default_times(TIMES) == pytest.approx([1.25e-4, 2.5e-4, 3.75e-4, 5.0e-4], rel=1e-12)
    steps = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]  # exact in binary: 2.5 is a true tie
    assert select_frames(steps, default_times(steps)) == [1, 2, 4, 5]
    assert default_times([2.0, 6.0]) == [3.0, 4.0, 5.0, 6.0]


def test_centre_node_is_the_node_nearest_the_bounding_box_centre():
    points = synth.lattice((9, 7), 2)
    index = centre_node(points)
    assert np.allclose(points[index], [4e-3, 3e-3, 0.0])
    points3 = synth.lattice((5, 4, 3), 3)
    index = centre_node(points3)
    centre = np.array([2e-3, 1.5e-3, 1e-3])
    assert np.linalg.norm(points3[index] - centre) == np.min(np.linalg.norm(points3 - centre, axis=1))
    assert index == int(np.argmin(np.linalg.norm(points3 - centre, axis=1)))  # lowest index of the ties
