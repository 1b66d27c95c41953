"""Time stamps at half or twice the sensor's rate: named by the gait's plausibility and the consistency scan, batch
and live; never on a real recording as recorded.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from footzoo import Pipeline
from footzoo.core.data import Recording
from footzoo.core.errors import SensorWarning
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


@pytest.mark.parametrize("sim, factor", [
    ({"n_strides": 5}, 2.0),  # a short walk: five swings, fewer strides than the gait is judged on
    ({"n_strides": 10, "cycle": 1.4}, 0.5),  # a slow walk at twice the rate: each swing only half-turned
    ({"path": "stairs", "n_strides": 5}, 0.5),
])
def test_time_stamps_at_half_or_twice_the_rate_are_named_batch_and_live(sim, factor):
    true = simulate(rate=100.0, noise=NoiseModel(seed=1), **sim)
    rec = _restamped(true, factor)
    res, found = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(rec))
    finding = res.diagnostics["sensor"]["plausibility"]["rate"]
    assert finding["rate_factor"] == pytest.approx(1.0 / factor, rel=0.01) and finding["likely_rate"] == 100.0
    assert any(f"probably sampled at 100 Hz, not {100.0 / factor:g} Hz" in m and "rate: 100}" in m
               and f"t × {1.0 / factor:g}" in m for m in found), found
    clean, quiet = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(_restamped(true, 1.0)))
    assert "plausibility" not in clean.diagnostics["sensor"] and not quiet  # the same walk at its real rate
    stream = Stream(Pipeline.from_dict(BASE), rate=rec.rate)  # the stamps' rate: what a user would pass
    _, live = _sensor_warnings(lambda: stream.run(rec, chunk=np.array([1, 17, 5, 64])))
    online = stream.sensor["plausibility"]["rate"]  # the same strides and swings, the same verdict
    assert (online["likely_rate"], online["until_sample"]) == (finding["likely_rate"], finding["until_sample"])
    assert online["costs"] == pytest.approx(finding["costs"], abs=1e-6)


def test_the_distance_of_a_walk_stamped_at_half_its_rate_is_what_the_warning_says():
    true = simulate(n_strides=5, rate=100.0, noise=NoiseModel(seed=1))
    res, _ = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(_restamped(true, 2.0)))
    travelled = np.linalg.norm(res.pos[-1, :2] - res.pos[0, :2])
    assert travelled > 3.0 * np.linalg.norm(true.truth.pos[-1, :2] - true.truth.pos[0, :2])


def test_a_batch_run_scans_in_blocks_until_decided_with_the_finding_of_one_push():
    from footzoo.filters.consistency import ConsistencyScan

    class Counted(ConsistencyScan):
        def _push(self, k, t, acc, gyr):  # what the scan itself reads (push_recording: not through push)
            self.last_pushed = int(k[-1])
            super()._push(k, t, acc, gyr)

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


# a restamped trial keeps its gaps, which the recording bridges again (expected warning)
@pytest.mark.filterwarnings(GAPS_BRIDGED)
@pytest.mark.slow
def test_no_real_recording_is_said_to_be_at_the_wrong_rate_and_restamped_ones_are():
    data_file("pyshoe_vicon")
    from ..conftest import DATA, load_benchmark

    relabel = load_benchmark("relabel")
    pipeline = Pipeline.from_yaml("recommended")
    named = wrong = total = 0
    for dataset, rec in relabel.recordings(DATA, {"pyshoe", "gaitmap", "xio", "koroglu"}):
        for case in relabel.cases(dataset, rec):
            if case["kind"] == "clean" or (case["kind"] == "rate" and case["factor"] in (2.0, 0.5)
                                           and "time stamps" in case["case"]):
                row = relabel.run_case(pipeline, rec.name, case)
                if case["kind"] == "clean":
                    assert not row["caught"], (rec.name, row["named"])  # as recorded: nothing named
                else:
                    total += 1
                    named += row["right"] or row["alternative"]
                    wrong += row["caught"] and not (row["right"] or row["alternative"])
    # 84 restamped files (benchmarks/relabel.md): 80 named with the real rate, none with another; not the crawl (×2,
    # ×½), the upside-down slow walk and the shortest-stepped walk (×½): benchmarks/relabel_misses.md
    assert total == 84 and named >= 80 and wrong == 0


@pytest.mark.parametrize("shift, outside", [(100.0, True), (0.0, False)])
def test_a_reference_on_another_clock_is_named_as_the_reason_no_stride_matched(shift, outside):
    # the samples stamped from another origin than the reference strides (e.g. a stream's clock, truth=rec.truth)
    import pandas as pd

    from footzoo.core.data import Truth
    from footzoo.evaluation.validity import checked_metrics

    t = np.arange(0.0, 15.0, 0.01) + shift
    truth = Truth(steps=pd.DataFrame({"start_s": [np.nan, 2.6], "to_s": [2.1, 3.1], "end_s": [2.6, 3.6]}))
    values = {"matched_strides": 0.0, "ic_error_median_abs_s": 0.0}
    out, notes = checked_metrics(values, {}, truth, t)
    assert np.isnan(out["ic_error_median_abs_s"])
    said = notes["ic_error_median_abs_s"]
    assert said.startswith("no estimated stride matched a reference stride")
    assert (("the reference's strides (t = 2.10-3.60 s) all lie outside the recording (t = 100.00-114.99 s)" in said)
            == outside), said
