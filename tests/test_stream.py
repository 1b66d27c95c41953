"""Live streaming gives what the batch run gives, for causal pipelines."""

import numpy as np
import pytest

from footzoo import ConfigError, Pipeline, Recording, RecordingError
from footzoo.runtime.stream import Stream
from footzoo.sim import NoiseModel, simulate

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=12, profile="physical", rate=100.0, noise=NoiseModel(seed=3), distance_sensors=True,
                    clearance=0.1)


@pytest.mark.parametrize("config", [
    "nguyen2016",
    {"orientation": {"type": "ins"}, "detector": {"type": "dgp"},
     "corrections": [{"type": "zupt"}, {"type": "height_distance"}]},
])
def test_streamed_results_equal_the_batch_results(walk, config):
    p = Pipeline.from_yaml(config) if isinstance(config, str) else Pipeline.from_dict(config)
    batch = p.run(walk)
    live = Stream(p).run(walk)
    assert len(live["t"]) == walk.n
    np.testing.assert_array_equal(live["stance"], batch.stance)
    np.testing.assert_allclose(live["pos"], batch.pos, rtol=0, atol=1e-12)
    np.testing.assert_allclose(live["quat"], batch.quat, rtol=0, atol=1e-12)
    np.testing.assert_allclose(live["vel"], batch.vel, rtol=0, atol=1e-12)


def test_push_returns_none_until_the_still_start_is_seen(walk):
    s = Stream(Pipeline.from_yaml("nguyen2016"))
    assert s.push(walk.t[0], walk.acc[0], walk.gyr[0], walk.mag[0]) is None
    outs = [s.push(walk.t[k], walk.acc[k], walk.gyr[k], walk.mag[k]) for k in range(1, 80)]
    est = outs[-1]
    assert est is not None and set(est) == {"t", "quat", "pos", "vel", "stance"}
    assert est["t"] == walk.t[79]


def test_non_causal_pipelines_are_rejected_with_the_reason():
    with pytest.raises(ConfigError, match=r"detector 'angular_rate_fsm' looks ahead or dates switches back"):
        Stream(Pipeline.from_yaml("yun2012"))
    with pytest.raises(ConfigError, match=r"detector 'windowed'"):
        Stream(Pipeline.from_yaml("duong2015_zupt"))
    # a smoother runs backwards: a stream would silently give the forward filter's estimate instead
    d = Pipeline.from_yaml("nguyen2016").to_dict()
    d["smoother"] = "rts"
    with pytest.raises(ConfigError, match=r"smoother 'rts' runs backwards .*live: smoother: none"):
        Stream(Pipeline.from_dict(d))


def test_bad_live_input_is_reported(walk):
    s = Stream(Pipeline.from_yaml("nguyen2016"))
    s.push(walk.t[0], walk.acc[0], walk.gyr[0])
    with pytest.raises(RecordingError, match="samples must arrive in order"):
        s.push(walk.t[0], walk.acc[0], walk.gyr[0])
    with pytest.raises(RecordingError, match="non-finite sample"):
        s.push(walk.t[1], [np.nan, 0, 0], walk.gyr[1])
    spinning = Stream(Pipeline.from_yaml("nguyen2016"), rate=100.0, max_wait=3.0)
    with pytest.raises(RecordingError, match="found no still period.*first 3.0 s"):
        for k in range(400):  # turning at 1 rad/s: never still
            spinning.push(k / 100.0, [0.0, 0.0, -9.81], [0.0, 0.0, 1.0])


def test_a_stream_that_starts_moving_waits_for_the_first_still_period_and_equals_the_batch(walk):
    p = Pipeline.from_yaml("nguyen2016")
    k0 = int(np.searchsorted(walk.t, 3.0))  # start mid-walk: the batch carries the attitude back
    rec = Recording(t=walk.t[k0:] - walk.t[k0], acc=walk.acc[k0:], gyr=walk.gyr[k0:], mag=walk.mag[k0:])
    batch = p.run(rec)
    s = Stream(p, rate=rec.rate, max_wait=60.0)  # this walk's only 0.5 s still period is at its end
    outs = [s.push(rec.t[k], rec.acc[k], rec.gyr[k], rec.mag[k]) for k in range(rec.n)]
    assert outs[0] is None and outs[-1] is not None
    first = next(k for k, o in enumerate(outs) if o is not None)
    np.testing.assert_allclose(outs[-1]["pos"], batch.pos[-1], rtol=0, atol=1e-9 * np.abs(batch.pos).max())
    assert first > 0.5 * rec.rate  # it waited for the still period


def test_distance_readings_missing_on_some_samples_count_as_no_reading(walk):
    p = Pipeline.from_dict({"orientation": {"type": "ins"}, "detector": {"type": "dgp"},
                            "corrections": [{"type": "zupt"}, {"type": "height_distance"}]})
    s = Stream(p, rate=walk.rate)
    for k in range(200):
        s.push(walk.t[k], walk.acc[k], walk.gyr[k], dist=None if k % 3 == 1 else walk.dist[k])
    late = Stream(p, rate=walk.rate)
    late.push(walk.t[0], walk.acc[0], walk.gyr[0])
    with pytest.raises(RecordingError, match="distance readings started after the first sample"):
        late.push(walk.t[1], walk.acc[1], walk.gyr[1], dist=walk.dist[1])


@pytest.mark.parametrize("trial", ["2017-11-22-11-22-03", "2017-11-22-11-38-45"])
def test_stream_equals_batch_on_real_walking_trials(trial):
    """Every shipped causal config, live on a PyShoe walking trial, gives the batch result (1e-9)."""
    import glob

    from footzoo import load
    from tests.conftest import data_file

    rec = load(data_file("pyshoe_vicon", f"{trial}.mat"), format="pyshoe")
    causal = []
    for path in sorted(glob.glob("footzoo/config/builtin/*.yaml")):
        if "study" in path:
            continue
        p = Pipeline.from_yaml(path)
        try:
            Stream(p)
        except ConfigError:
            continue
        causal.append(p)
    assert causal
    for p in causal:
        batch = p.run(rec)
        live = Stream(p).run(rec)
        np.testing.assert_array_equal(live["stance"], batch.stance)
        assert np.abs(live["pos"] - batch.pos).max() <= 1e-9 * max(np.abs(batch.pos).max(), 1.0), p.name
