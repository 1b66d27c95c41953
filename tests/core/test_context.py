"""The run context: one rate, gravity and time base per run."""

from __future__ import annotations

import numpy as np
import pytest

from footzoo import ConfigError
from footzoo.core.context import RunContext
from footzoo.sim import simulate


def test_a_batch_context_takes_the_recordings_median_rate_and_start():
    rec = simulate(n_strides=3, rate=250.0)
    ctx = RunContext.of(rec, gravity=9.8)
    assert ctx.rate == pytest.approx(250.0) and ctx.rate == rec.rate
    assert ctx.t0 == rec.t[0] and ctx.gravity == 9.8 and ctx.name == rec.name
    assert ctx.period == pytest.approx(0.004)


def test_durations_become_the_nearest_whole_number_of_samples_halves_up():
    ctx = RunContext(rate=200.0)
    assert ctx.samples(0.025) == 5 and ctx.samples(0.0125) == 3 and ctx.samples(0.0) == 0
    assert ctx.samples(0.0, minimum=1) == 1 and ctx.seconds(40) == pytest.approx(0.2)


def test_the_time_stamps_alone_give_their_median_rate():
    t = np.cumsum(np.r_[0.0, np.full(99, 0.01), 0.05, np.full(50, 0.01)])
    assert RunContext.from_time(t).rate == pytest.approx(100.0)
    with pytest.raises(ConfigError, match="two time stamps"):
        RunContext.from_time(t[:1])


@pytest.mark.parametrize("rate", [0.0, -100.0, float("nan"), float("inf"), "100"])
def test_a_rate_that_is_not_a_positive_number_is_refused(rate):
    with pytest.raises(ConfigError, match="positive number of Hz"):
        RunContext(rate=rate)
