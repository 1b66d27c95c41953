"""Bad live input: a stream made with the wrong rate, an accelerometer whose unit changes mid-stream."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import footzoo
from footzoo.core.errors import RecordingError
from footzoo.sim import simulate


@pytest.fixture(scope="module")
def sim_walk():
    from footzoo.sim import NoiseModel

    return simulate(n_strides=10, rate=100.0, noise=NoiseModel(seed=1))


def test_a_stream_made_with_the_wrong_rate_refuses_at_its_start(sim_walk):
    from footzoo import Pipeline, Stream

    stream = Stream(Pipeline.from_yaml("nguyen2016"), rate=2 * sim_walk.rate)
    with pytest.raises(RecordingError, match=r"come at 100 Hz, but the stream was made with rate=200 Hz.*rate=100"):
        stream.run(sim_walk)
    near = Stream(Pipeline.from_yaml("nguyen2016"), rate=sim_walk.rate * 1.05)  # a nominal rate, 5 % off: fine
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert np.isfinite(near.run(sim_walk)["pos"]).all()


def test_an_accelerometer_unit_that_changes_mid_stream_is_warned_where_it_changes(sim_walk):
    from footzoo import Pipeline, Stream
    from footzoo.core.errors import SensorWarning

    half = sim_walk.n // 2
    stream = Stream(Pipeline.from_yaml("nguyen2016"), rate=sim_walk.rate)
    with pytest.warns(SensorWarning, match=r"accelerometer reads 0\.99\d? \(≈ 1: in g\?"):
        for i in range(sim_walk.n):
            stream.push(sim_walk.t[i], sim_walk.acc[i] / (9.81 if i >= half else 1.0), sim_walk.gyr[i])
        stream.close()
    finding = stream.sensor["acc_scale"]
    assert finding["first"] >= half and finding["magnitude"] == pytest.approx(1.0, abs=0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SensorWarning)  # the same walk in m/s² throughout: no finding
        res = footzoo.Pipeline.from_yaml("nguyen2016").run(sim_walk)
    assert "acc_scale" not in res.diagnostics["sensor"]


@pytest.mark.slow  # a batch run and a stream of a 10-stride walk: 2-3 s
def test_a_stream_reports_the_accelerometer_gain_it_applied_as_the_batch_run_does(sim_walk, tmp_path):
    from dataclasses import replace

    from footzoo import Pipeline, Result, Stream

    off = replace(sim_walk, acc=sim_walk.acc * 1.2)  # a still start 20 % off g: a gain error, corrected
    pipeline = Pipeline.from_yaml("nguyen2016")
    stream = Stream(pipeline, rate=off.rate, keep=True)
    batch, batch_said = _sensor_warnings(pipeline.run, off)
    live_said = _sensor_warnings(stream.run, off)[1]
    for said in (batch_said, live_said):
        # the gain is named once; the checks of the estimate read the corrected signals: no false "wrong rate"
        assert len(said) == 1 and "% off g" in said[0] and "diagnostics['acc_gain']" in said[0], said
    live = stream.result()
    assert live.diagnostics["acc_gain"] == batch.diagnostics["acc_gain"]
    assert live.diagnostics["acc_gain"]["gain"] == pytest.approx(1 / 1.2, rel=0.01)
    live.save(tmp_path / "live")
    assert Result.load(tmp_path / "live").diagnostics["acc_gain"] == batch.diagnostics["acc_gain"]


def _sensor_warnings(fn, *args):
    """``fn(*args)`` and the texts of the SensorWarnings it gave."""
    from footzoo.core.errors import SensorWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn(*args)
    return out, [str(w.message) for w in caught if issubclass(w.category, SensorWarning)]


@pytest.mark.parametrize("second, match", [
    (slice(5, 8), r"time went from 0\.09 s to 0\.05 s: samples must arrive in order"),  # back in time
    ("nan", r"non-finite sample at t = 0\.1: acc = \[nan, nan, nan\]"),
])
def test_a_stream_error_quotes_numpy_time_stamps_as_plain_numbers(sim_walk, second, match):
    from footzoo import Pipeline, Stream

    t, acc, gyr = sim_walk.t, sim_walk.acc.copy(), sim_walk.gyr
    stream = Stream(Pipeline.from_yaml("nguyen2016"), rate=sim_walk.rate)
    stream.extend(t[:10], acc[:10], gyr[:10])
    if second == "nan":
        acc[10] = np.nan
        second = slice(10, 20)
    with pytest.raises(RecordingError, match=match) as info:
        stream.extend(t[second], acc[second], gyr[second])
    assert "np.float64" not in str(info.value)


@pytest.mark.parametrize("swap", [True, False])
def test_a_block_with_acc_and_gyr_swapped_is_named_as_such(sim_walk, swap):
    from footzoo.core.checks import validate_block

    t, acc, gyr = sim_walk.t[:300], sim_walk.acc[:300], sim_walk.gyr[:300].copy()
    if not swap:  # one corrupt gyro sample, the channels in their places: no swap hint
        gyr[100] = [0.0, 60.0, 0.0]
    with pytest.raises(RecordingError, match="beyond any body-worn IMU") as info:
        validate_block(t, gyr, acc) if swap else validate_block(t, acc, gyr)
    assert ("acc and gyr look swapped: the median |gyr| is" in str(info.value)) == swap


@pytest.mark.parametrize("kwargs, message", [
    ({"rate": -100}, r"^Stream: rate must be a positive number of Hz, got -100$"),
    ({"max_wait": 0}, r"^Stream: max_wait must be a positive number of seconds, got 0$"),
    ({"engine": "quick"}, r"^Stream: engine must be one of \['auto', 'fast', 'reference'\], got 'quick'$"),
])
def test_a_bad_stream_argument_is_named_as_the_streams_not_the_pipelines(kwargs, message):
    with pytest.raises(footzoo.ConfigError, match=message):
        footzoo.Stream(footzoo.Pipeline.from_yaml("recommended_live"), **kwargs)


def test_a_pipeline_that_cannot_run_live_says_so_before_the_arguments():
    with pytest.raises(footzoo.ConfigError, match=r"^this pipeline cannot run live: smoother 'rts' .*; rate must be"):
        footzoo.Stream(footzoo.Pipeline.from_yaml("recommended"), rate=-1)
