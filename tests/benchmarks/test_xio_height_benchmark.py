"""benchmarks/xio_height.py: its edge velocities, predicted climb and x-io segmentation on hand-derived cases (the
full run needs x-io's recording)."""

import numpy as np
import pytest

from ..conftest import load_benchmark

RATE = 400.0


@pytest.fixture(scope="module")
def xh():
    return load_benchmark("xio_height")


def stance_case():
    """A still start, a swing, a 0.5 s stance whose first 0.1 s decelerates a sinking sensor, a swing, a still end."""
    t = np.arange(int(2.0 * RATE)) / RATE
    stance = (t < 0.4) | ((t >= 0.8) & (t < 1.3)) | (t >= 1.7)
    a_down = np.zeros(len(t))
    gyr = np.zeros((len(t), 3))
    settle = (t >= 0.8) & (t < 0.9)
    a_down[settle] = -0.5  # m/s², down positive: the sensor sinks at 0.05 m/s at the stance start and stops
    gyr[settle, 1] = 0.4  # rad/s: the foot still turning flat
    gyr[~stance, 1] = 3.0
    return t, a_down, gyr, stance


def test_edge_velocities_integrate_from_the_quiet_middle_out_to_the_edges(xh):
    t, a_down, gyr, stance = stance_case()
    edges = xh.edge_velocities(t, a_down, gyr, stance)
    assert edges.shape == (1, 6)  # the still start and end are not inner stances
    v_start, v_end, w_first, duration, a, b = edges[0]
    # 40 samples of -0.5 m/s² before the quiet part: the sensor sank at 40 × 0.5 / 400 = 0.05 m/s (the first
    # sample's own interval lies before the stance, so 39 of them count)
    assert v_start == pytest.approx(39 * 0.5 / RATE, abs=1e-12)
    assert v_end == pytest.approx(0.0, abs=1e-12)
    assert w_first == pytest.approx(0.4)
    assert duration == pytest.approx(0.5 - 1 / RATE)
    assert (int(a), int(b)) == (int(0.8 * RATE), int(1.3 * RATE))


def test_predicted_climb_is_half_the_edge_velocity_times_the_swing(xh):
    t = np.arange(int(3.0 * RATE)) / RATE
    # two inner stances: [1.0, 1.5) and [2.2, 2.6); the swing between them lasts from t[599] to t[880]
    edges = np.array([[0.0, -0.02, 0.0, 0.5, 400, 600], [0.06, 0.0, 0.0, 0.4, 880, 1040]])
    per_swing = xh.predicted_climb(t, edges)
    T = t[880] - t[599]
    np.testing.assert_allclose(per_swing, [[0.06 * T / 2, -0.02 * T / 2]])


def test_xio_moving_widens_each_moving_sample_by_100_ms_on_both_sides(xh):
    a = np.zeros((400, 3))
    a[200, 0] = 4.0  # above x-io's 3 m/s²
    moving = xh.xio_moving(a, RATE)
    assert np.flatnonzero(moving).tolist() == list(range(160, 241))
