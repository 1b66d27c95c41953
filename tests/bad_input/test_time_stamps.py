"""Time stamps at half or twice the sensor's rate: named by the consistency scan, batch and live; never on a real
recording as recorded.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import footzoo
from footzoo import Pipeline
from footzoo.core.data import Recording
from footzoo.core.errors import FootzooWarning, SensorWarning
from footzoo.runtime.stream import Stream
from footzoo.sim import NoiseModel, simulate

from ..conftest import GAPS_BRIDGED, data_file


def _sensor_warnings(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn()
    return out, [str(w.message) for w in caught if issubclass(w.category, SensorWarning)]


BASE = {"name": "physics", "orientation": {"type": "madgwick", "use_magnetometer": False},
        "detector": {"type": "angular_rate_fsm"}, "corrections": [{"type": "zvu_dedrift"}]}


def _restamped(rec: Recording, factor: float) -> Recording:
    """``rec``'s samples with time stamps ``factor`` times too far apart (2: stamped at half the real rate)."""
    return Recording(t=(rec.t - rec.t[0]) * factor, acc=rec.acc, gyr=rec.gyr, meta={"name": "restamped"})


@pytest.mark.parametrize("sim, factor, words", [
    ({"n_strides": 5}, 2.0, "half"),  # a short walk: five swings, fewer than the absolute rule decides on
    ({"n_strides": 10, "cycle": 1.4}, 0.5, "twice"),  # a slow walk at twice the rate: each swing only half-turned
    ({"path": "stairs", "n_strides": 5}, 0.5, "twice"),
])
def test_time_stamps_at_half_or_twice_the_rate_are_named_batch_and_live(sim, factor, words):
    true = simulate(rate=100.0, noise=NoiseModel(seed=1), **sim)
    rec = _restamped(true, factor)
    res, found = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(rec))
    finding = res.diagnostics["sensor"]["consistency"]
    assert finding["cause"] == f"the time stamps are at {words} the sensor's rate"
    assert finding["rate_factor"] == factor and finding["likely_rate"] == pytest.approx(100.0, rel=0.01)
    assert finding["explained_residual"] * 2.0 <= finding["residual"]
    assert any(f"samples at {factor:g}× that, about 100 Hz" in m and "rate=100" in m for m in found), found
    clean, quiet = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(_restamped(true, 1.0)))
    assert "consistency" not in clean.diagnostics["sensor"] and not quiet  # the same walk at its real rate
    stream = Stream(Pipeline.from_dict(BASE), rate=rec.rate)  # the stamps' rate: what a user would pass
    _, live = _sensor_warnings(lambda: stream.run(rec, chunk=np.array([1, 17, 5, 64])))
    assert stream.sensor["consistency"] == finding  # the same swings, the same numbers


def test_the_distance_of_a_walk_stamped_at_half_its_rate_is_what_the_warning_says():
    true = simulate(n_strides=5, rate=100.0, noise=NoiseModel(seed=1))
    res, _ = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(_restamped(true, 2.0)))
    travelled = np.linalg.norm(res.pos[-1, :2] - res.pos[0, :2])
    assert travelled > 3.0 * np.linalg.norm(true.truth.pos[-1, :2] - true.truth.pos[0, :2])


def test_a_batch_run_scans_in_blocks_until_decided_with_the_finding_of_one_push():
    from footzoo.filters.consistency import ConsistencyScan

    class Counted(ConsistencyScan):
        def push(self, k, t, acc, gyr):
            self.last_pushed = int(k[-1])
            super().push(k, t, acc, gyr)

    walk = simulate(n_strides=80, rate=100.0, noise=NoiseModel(seed=3))
    for r in (walk, _restamped(walk, 2.0)):
        one, blocks = ConsistencyScan(r.rate, name="one"), Counted(r.rate, name="blocks")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SensorWarning)
            one.push(np.arange(r.n), r.t, r.acc, r.gyr)
            blocks.push_recording(r.t, r.acc, r.gyr, block=500)
            assert blocks.finish() == one.finish()
        assert blocks.swings == one.swings[:len(blocks.swings)]  # one push measures every swing it holds
        assert blocks.done and blocks.last_pushed < r.n - 1  # decided before the walk's end: the rest is not read


def _real_recordings() -> list[Recording]:
    import glob

    folder = data_file("pyshoe_vicon")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FootzooWarning)
        recs = [footzoo.load(f) for f in sorted(glob.glob(str(folder / "*.mat")))]
        recs += [footzoo.load(data_file("gaitmap_example", "imu_sample.csv"), foot=f) for f in ("left", "right")]
        recs += [footzoo.load(data_file("xio_gait_tracking", "short_walk.csv"))]
        recs += [footzoo.load(p) for p in sorted(data_file("koroglu_gcp").glob("*.csv"))]
    return recs


# a restamped trial keeps its gaps, which the recording bridges again (expected warning)
@pytest.mark.filterwarnings(GAPS_BRIDGED)
@pytest.mark.slow
def test_no_real_recording_is_said_to_be_at_the_wrong_rate_and_restamped_ones_are():
    from footzoo.filters.consistency import ConsistencyScan

    named = 0
    recs = _real_recordings()
    for rec in recs:
        for factor in (1.0, 2.0, 0.5):
            r = _restamped(rec, factor) if factor != 1.0 else rec
            scan = ConsistencyScan(r.rate, name=rec.name)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", SensorWarning)
                scan.push(np.arange(r.n), r.t, r.acc, r.gyr)
                cause = scan.finish().get("cause", "")
            if factor == 1.0:
                assert not cause, (rec.name, cause)  # as recorded: consistent
            elif cause:
                assert ("half" if factor == 2.0 else "twice") in cause, (rec.name, factor, cause)
                named += 1
    # 84 restamped files: 69 named (60 by the absolute rule alone); not the unusual-motion and upside-down
    # trials, two walks, and runs with too few quasi-static instants
    assert named >= 66
