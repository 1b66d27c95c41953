"""A live stream used wrongly, and a channel that drops out: named with the time and the fix, batch and live.

* a stream run twice, run after pushes, or pushed after it ended: it takes one recording;
* the magnetometer stopping (or starting) part-way: the first sample decides;
* a sensor that repeats one exact reading while the other one moves (a dropout filled by a logger): a
  SensorWarning naming the sensor and the time, batch and live, instead of a unit or rate fault that is not.
"""

from __future__ import annotations

import warnings

import pytest

from footzoo import Pipeline, RecordingError
from footzoo.core.data import Recording
from footzoo.core.errors import SensorWarning
from footzoo.core.sanity import FROZEN_MIN_SAMPLES, find_frozen
from footzoo.runtime.stream import Stream
from footzoo.sim import NoiseModel, simulate


@pytest.fixture(scope="module")
def walk() -> Recording:
    return simulate(n_strides=4, rate=100.0, noise=NoiseModel(seed=1))


@pytest.fixture(scope="module")
def pipeline() -> Pipeline:
    return Pipeline.from_yaml("nguyen2016")


def _run_then(pipeline, walk, action):
    stream = Stream(pipeline, rate=walk.rate)
    stream.run(walk, chunk=100)
    return lambda: action(stream)


def _pushed_then_run(pipeline, walk):
    stream = Stream(pipeline, rate=walk.rate)
    for k in range(50):
        stream.push(walk.t[k], walk.acc[k], walk.gyr[k])
    return lambda: stream.run(walk)


def _mag(pipeline, walk, first: int, stop: bool):
    def action():
        stream = Stream(pipeline, rate=walk.rate)
        for k in range(first + 5):
            has = (k < first) if stop else (k >= first)
            stream.push(walk.t[k], walk.acc[k], walk.gyr[k], walk.mag[k] if has else None)
    return action


def _gyr_missing(pipeline, walk, first: int):
    def action():
        stream = Stream(pipeline, rate=walk.rate)
        for k in range(first + 1):
            stream.push(walk.t[k], walk.acc[k], walk.gyr[k] if k < first else None)
    return action


def _block_missing(pipeline, walk, first: int, channel: str):
    def action():
        stream = Stream(pipeline, rate=walk.rate)
        stream.extend(walk.t[:first], walk.acc[:first], walk.gyr[:first])
        block = {"acc": walk.acc[first:first + 50], "gyr": walk.gyr[first:first + 50], channel: None}
        stream.extend(walk.t[first:first + 50], block["acc"], block["gyr"])
    return action


USES = [
    ("run-twice", lambda p, w: _run_then(p, w, lambda s: s.run(w)),
     "Stream.run(): this stream has run (or was closed) already; a stream takes one recording: make a new Stream"),
    ("push-after-run", lambda p, w: _run_then(p, w, lambda s: s.push(w.t[-1] + 0.01, w.acc[0], w.gyr[0])),
     "Stream.push(): the stream is closed (close() or run() ended it after "),
    ("extend-after-close", lambda p, w: _run_then(p, w, lambda s: s.extend(w.t[-2:] + 1.0, w.acc[:2], w.gyr[:2])),
     "Stream.extend(): the stream is closed"),
    ("run-after-pushes", _pushed_then_run,
     "Stream.run() pushes a whole recording from its first sample, but this stream was pushed 50 sample(s) already "
     "(up to t = 0.49 s)"),
    ("mag-stops", lambda p, w: _mag(p, w, 120, stop=True),
     "mag stopped at t = 1.2 s (sample 120) after coming with every sample before: a channel must come with every "
     "sample or with none"),
    ("mag-starts", lambda p, w: _mag(p, w, 120, stop=False),
     "mag started at t = 1.2 s (sample 120), after 120 sample(s) without it"),
    ("gyr-missing", lambda p, w: _gyr_missing(p, w, 150),
     "gyr is missing (None) at t = 1.5: every sample needs gyr (rad/s, 3 numbers); a sensor that dropped out cannot "
     "be bridged"),
    # a block (extend) without one of the two channels every sample needs: was "zero-dimensional arrays cannot be
    # concatenated" from inside the stream
    ("gyr-missing-block", lambda p, w: _block_missing(p, w, 150, "gyr"),
     "gyr is missing (None) in the block from t = 1.5: every sample needs gyr (rad/s, 3 numbers, here (50, 3)); a "
     "sensor that dropped out cannot be bridged"),
    ("acc-missing-block", lambda p, w: _block_missing(p, w, 150, "acc"),
     "acc is missing (None) in the block from t = 1.5: every sample needs acc (m/s^2, 3 numbers, here (50, 3))"),
]


@pytest.mark.parametrize("make, fragment", [u[1:] for u in USES], ids=[u[0] for u in USES])
def test_a_stream_used_wrongly_says_what_and_where(make, fragment, pipeline, walk):
    action = make(pipeline, walk)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SensorWarning)
        with pytest.raises(RecordingError) as info:
            action()
    assert fragment in str(info.value)


def test_closing_twice_is_harmless_and_gives_nothing_more(pipeline, walk):
    stream = Stream(pipeline, rate=walk.rate)
    out = stream.run(walk, chunk=100)
    assert len(out["t"]) == walk.n and len(stream.close()["t"]) == 0


def test_an_empty_packet_adds_nothing_and_changes_no_estimate(pipeline, walk):
    """A read that found no new sample: was 'an empty block: give at least one sample', an error mid-recording."""
    import numpy as np

    plain = Stream(pipeline, rate=walk.rate).run(walk, chunk=100)
    stream = Stream(pipeline, rate=walk.rate)
    parts = []
    for a in range(0, walk.n, 100):
        sl = slice(a, a + 100)
        stream.extend(walk.t[sl], walk.acc[sl], walk.gyr[sl], None if walk.mag is None else walk.mag[sl])
        assert stream.extend(np.empty(0), np.empty((0, 3)), np.empty((0, 3))) is None
        parts.append(stream.final())
    parts.append(stream.close())
    np.testing.assert_array_equal(np.concatenate([p["pos"] for p in parts]), plain["pos"])


def _dropped(walk: Recording, sensor: str, first: int) -> Recording:
    arrays = {"acc": walk.acc.copy(), "gyr": walk.gyr.copy()}
    arrays[sensor][first:] = 0.0 if sensor == "gyr" else arrays[sensor][first - 1]  # zeros, or the last value held
    return arrays


@pytest.mark.parametrize("sensor, other", [("gyr", "accelerometer"), ("acc", "gyroscope")])
def test_a_sensor_that_drops_out_is_named_batch_and_live(sensor, other, walk, pipeline):
    first = 200
    arrays = _dropped(walk, sensor, first)
    name = {"gyr": "gyroscope", "acc": "accelerometer"}[sensor]
    pattern = rf"the {name} repeats one reading .* exactly from t = (1\.990|2\.000) s .* while the {other} moves"
    with pytest.warns(SensorWarning, match=pattern + ": that channel dropped out"):
        rec = Recording(t=walk.t, meta={"name": "dropout"}, **arrays)
    found = rec.meta["sanity"]["frozen"]
    assert [f["sensor"] for f in found] == [sensor] and found[0]["first"] in (first - 1, first)
    assert found[0]["last"] == walk.n - 1
    stream = Stream(pipeline, rate=walk.rate)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for k in range(walk.n):
            stream.push(walk.t[k], arrays["acc"][k], arrays["gyr"][k])
        stream.close()
    live = stream.sensor["frozen"]
    assert [f["sensor"] for f in live] == [sensor] and live[0]["first"] == found[0]["first"]
    texts = [str(w.message) for w in caught if issubclass(w.category, SensorWarning)]
    assert sum("dropped out" in t for t in texts) == 1  # once, however long it lasts
    assert not any("unit or scale is wrong" in t for t in texts)  # not taken for a unit fault


def test_recordings_without_a_dropout_are_not_called_frozen(walk):
    assert find_frozen(walk.t, walk.acc, walk.gyr) == []
    still = simulate(n_strides=2, rate=100.0)  # noise-free: both sensors repeat at rest, together
    assert find_frozen(still.t, still.acc, still.gyr) == []
    short = _dropped(walk, "gyr", walk.n - FROZEN_MIN_SAMPLES + 2)  # too short to tell
    assert find_frozen(walk.t, short["acc"], short["gyr"]) == []
