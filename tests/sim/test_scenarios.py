"""Simulator scenarios beyond level walking: running, stairs, many laps (one-hour walks)."""

import numpy as np
import pytest

from footzoo.sim import SPEEDS, simulate

from .test_sim import strapdown


def test_run_is_straight_strides_at_running_speed():
    rec = simulate(path="run", n_strides=6, rate=200.0, profile="physical")
    length, cycle, stance_fraction, flat = SPEEDS["run"]
    steps = rec.truth.steps
    assert len(steps) == 6
    np.testing.assert_allclose(steps["stride_length"], length)
    np.testing.assert_allclose(np.diff(steps["end"]), cycle)
    assert rec.meta["name"] == "sim_run"
    # the sensor is still only while the foot is flat: that share of the contact (0.1 s of 0.3 s)
    still_time = rec.truth.stance.sum() / rec.rate - 2.0 - 1.0  # minus standing start and end
    assert still_time / (6 * cycle) == pytest.approx(stance_fraction * flat, abs=0.01)


def test_stairs_climb_and_descend_by_the_flight_height():
    rise, going, n = 0.17, 0.28, 4
    rec = simulate(path="stairs", n_strides=n, rise=rise, going=going, landing_strides=2, stride_length=1.0,
                   rate=100.0, cycle=1.2, clearance=0.1)
    tr = rec.truth
    stance_z = tr.pos[tr.stance, 2]
    # NED: up is −z; the landing is 2 n risers above the start, the end back on the ground floor
    assert stance_z.min() == pytest.approx(-2 * n * rise)
    assert tr.pos[-1, 2] == pytest.approx(0.0, abs=1e-12)
    horizontal = tr.steps["stride_length"].to_numpy()
    np.testing.assert_allclose(horizontal, [2 * going] * n + [1.0] * 2 + [2 * going] * n)
    # the truth is consistent: strapdown of the noise-free signals reproduces the climb
    _, _, pos = strapdown(rec)
    assert np.max(np.abs(pos[:, 2] - tr.pos[:, 2])) < 0.01


def test_laps_repeat_a_closed_path():
    one = simulate(path="rectangle", length=6.0, width=3.6, rate=50.0)
    three = simulate(path="rectangle", length=6.0, width=3.6, rate=50.0, laps=3)
    assert three.truth.closed_loop
    assert len(three.truth.steps) == 3 * len(one.truth.steps)
    assert three.truth.steps["stride_length"].sum() == pytest.approx(3 * 2 * (6.0 + 3.6), rel=0.01)
    np.testing.assert_allclose(three.truth.pos[-1], three.truth.pos[0], atol=1e-9)


def test_laps_on_an_open_path_is_refused():
    with pytest.raises(ValueError, match="laps applies to closed paths"):
        simulate(path="straight", n_strides=3, laps=2)
