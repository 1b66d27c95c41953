"""Trajectory metrics on hand-made trajectories."""

import numpy as np
import pytest

from footzoo.evaluation.metrics import (
    armse,
    intervals,
    loop_closure,
    path_length,
    pyshoe_error,
    rotate_about_vertical,
    yaw_alignment,
)


def square(n=400, side=10.0):
    s = np.linspace(0, 4, n, endpoint=False)
    pts = []
    for u in s:
        leg, f = int(u), u - int(u)
        corners = [(0, 0), (side, 0), (side, side), (0, side), (0, 0)]
        a, b = np.array(corners[leg]), np.array(corners[leg + 1])
        pts.append([*(a + f * (b - a)), 0.0])
    pts.append([0.0, 0.0, 0.0])
    return np.array(pts)


def test_path_length_and_loop_closure_of_a_square():
    p = square()
    assert path_length(p) == pytest.approx(40.0)
    p_open = p.copy()
    p_open[-1] = [0.3, 0.4, -1.2]
    lc = loop_closure(p_open)
    assert lc["loop_closure_xy_m"] == pytest.approx(0.5)
    assert lc["loop_closure_3d_m"] == pytest.approx(1.3)
    assert lc["loop_closure_xy_pct"] == pytest.approx(100 * 0.5 / lc["path_length_m"])


def test_yaw_alignment_recovers_a_known_rotation_and_offset():
    ref = square() + [2.0, 3.0, 0.5]
    est = rotate_about_vertical(square(), -0.7)
    assert yaw_alignment(est, ref) == pytest.approx(0.7)
    assert armse(est, ref) == pytest.approx(0.0, abs=1e-12)


def test_armse_of_a_constant_offset_after_alignment():
    ref = square()
    est = ref.copy()
    est[1:, 2] += 0.2  # vertical error after the start is not rotated away
    assert armse(est, ref) == pytest.approx(0.2 * np.sqrt((len(ref) - 1) / len(ref)))


def test_pyshoe_error_aligns_on_the_first_point_0p8m_away():
    ref = square()
    est = rotate_about_vertical(ref, 1.0)
    assert pyshoe_error(est, ref) == pytest.approx(0.0, abs=1e-12)
    # hand-derived: a straight walk north, estimated 10 % long and turned by 0.3 rad;
    # after alignment the error at distance x is 0.1 x in north only: sqrt((0.1 x)² / 2)
    x = np.linspace(0.0, 20.0, 201)
    line = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    est2 = rotate_about_vertical(1.1 * line, 0.3)
    assert pyshoe_error(est2, line) == pytest.approx(np.mean(0.1 * x / np.sqrt(2)), rel=1e-12)


def test_shape_mismatch_is_an_error():
    with pytest.raises(ValueError, match="same shape"):
        armse(np.zeros((5, 3)), np.zeros((4, 3)))


def test_stance_metrics_on_a_hand_made_case():
    from footzoo.evaluation.metrics import intervals, stance_scores, step_detection

    t = np.arange(40) * 0.01
    truth = np.zeros(40, bool)
    truth[2:8] = truth[12:18] = truth[22:28] = truth[32:38] = True
    det = np.zeros(40, bool)
    det[3:8] = True  # correct, onset 10 ms late
    det[12:14] = det[15:18] = True  # split
    det[19:20] = True  # false step
    # third true phase missed; the fourth merged with nothing else: correct, offset 10 ms early
    det[32:37] = True
    np.testing.assert_array_equal(intervals(det), [[3, 8], [12, 14], [15, 18], [19, 20], [32, 37]])
    r = step_detection(det, truth, t)
    assert (r["true_steps"], r["detected_steps"], r["correct"], r["missed"], r["split"], r["false_steps"]) == (
        4, 5, 2, 1, 1, 1)
    assert r["error_rate"] == pytest.approx((4 - 2 + 1) / 4)
    assert r["onset_error_mean_s"] == pytest.approx(0.005)
    assert r["offset_error_mean_s"] == pytest.approx(-0.005)
    s = stance_scores(det, truth)
    tp = 5 + 5 + 5
    assert s["precision"] == pytest.approx(tp / det.sum())
    assert s["recall"] == pytest.approx(tp / truth.sum())
    assert s["f1"] == pytest.approx(2 * s["precision"] * s["recall"] / (s["precision"] + s["recall"]))


def test_a_merged_detection_counts_both_true_phases_wrong():
    from footzoo.evaluation.metrics import step_detection

    t = np.arange(20) * 0.01
    truth = np.zeros(20, bool)
    truth[2:6] = truth[9:13] = True
    det = np.zeros(20, bool)
    det[2:13] = True
    r = step_detection(det, truth, t)
    assert r["correct"] == 0 and r["error_rate"] == 1.0


def test_intervals_are_the_true_runs_of_a_mask():
    np.testing.assert_array_equal(intervals(np.array([0, 1, 1, 0, 1, 0, 0, 1], bool)), [[1, 3], [4, 5], [7, 8]])
    np.testing.assert_array_equal(intervals(np.ones(4, bool)), [[0, 4]])
    assert intervals(np.zeros(5, bool)).shape == (0, 2) and intervals(np.zeros(0, bool)).shape == (0, 2)
    rng = np.random.default_rng(2)
    for p in (0.1, 0.5, 0.9):  # against the differences of the mask padded with False
        m = rng.random(1001) < p
        d = np.diff(np.concatenate([[0], m.astype(np.int8), [0]]))
        expected = np.column_stack([np.flatnonzero(d == 1), np.flatnonzero(d == -1)])
        got = intervals(m)
        assert got.dtype == np.int64
        np.testing.assert_array_equal(got, expected)
