"""The gait against the ranges of human gait (footzoo.core.plausibility): a wrong rate or gyroscope unit named once,
with its fix, batch and live."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from footzoo import Pipeline
from footzoo.core.data import Recording
from footzoo.core.errors import SensorWarning
from footzoo.core.plausibility import MARGIN, judge_rate, likely_rate
from footzoo.runtime.stream import Stream
from footzoo.sim import NoiseModel, simulate

BASE = {"name": "physics", "orientation": {"type": "madgwick", "use_magnetometer": False},
        "detector": {"type": "angular_rate_fsm"}, "corrections": [{"type": "zvu_dedrift"}]}
#: The medians of a walk as footzoo measures it (PyShoe's 2017-11-22 walks: 1.0–1.4 m at 85–115 steps/min, about
#: 0.1 m of clearance, 0.29–0.40 m per radian the foot turns).
WALK = {"strides": 20, "cadence_steps_min": 105.0, "stride_length_m": 1.3, "speed_m_s": 1.14, "clearance_m": 0.11,
        "swing_time_s": 0.8, "rotation_rad": 3.7, "rolling_m_rad": 0.35, "peak_rate_rad_s": 9.0}


def relabelled(gait: dict[str, float], f: float) -> dict[str, float]:
    """The walk read at ``f`` times its rate, by the laws of the module docstring: durations / f, rotations / f,
    lengths / f² (a double integral), the measured angular rate unchanged."""
    return {**gait, "cadence_steps_min": gait["cadence_steps_min"] * f,
            "stride_length_m": gait["stride_length_m"] / f**2,
            "speed_m_s": gait["speed_m_s"] / f, "clearance_m": gait["clearance_m"] / f**2,
            "swing_time_s": gait["swing_time_s"] / f, "rotation_rad": gait["rotation_rad"] / f,
            "rolling_m_rad": gait["rolling_m_rad"] / f}


def evidence(lowest: float) -> dict[str, object]:
    """Gyroscope-accelerometer residuals lowest at the time scale ``lowest``: 0.08 there, ×6 per doubling away (PyShoe's
    walks: 0.06–0.13 at the right scale, 3–4 times that at 1.5 times it, 3–14 at twice or half of it)."""
    scales = np.array([1.0, *(2.0 ** (k / 8.0) for k in range(-8, 9) if k)])
    return {"scales": scales, "residual": 0.08 * 6.0 ** np.abs(np.log2(scales / lowest)), "swings": 20}


def _sensor_warnings(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn()
    return out, [str(w.message) for w in caught if issubclass(w.category, SensorWarning)]


# --------------------------------------------------------------------------- the verdict, from numbers
def test_a_walk_as_declared_costs_nothing_and_is_not_named():
    verdict = judge_rate(WALK, evidence(1.0))
    assert verdict["factor"] is None and verdict["costs"][1.0] == 0.0


#: The issue's walk: 0.7 m strides at 81 steps/min read at twice its rate (0.17 m at 163 steps/min, 6 mm of clearance).
ISSUE = relabelled({**WALK, "cadence_steps_min": 81.5, "stride_length_m": 0.7, "speed_m_s": 0.48, "clearance_m": 0.025,
                    "rolling_m_rad": 0.3}, 2.0)


def test_the_gait_alone_names_no_rate():
    # outside the ranges of human gait, but a detector that splits every stride in two looks the same
    verdict = judge_rate(ISSUE, None)
    assert verdict["factor"] is None and verdict["costs"][1.0] - verdict["costs"][2.0] >= MARGIN


def test_the_gait_tips_residuals_too_shallow_to_name_a_rate_alone():
    shallow = {**evidence(2.0), "residual": 0.08 * 1.5 ** np.abs(np.log2(evidence(2.0)["scales"] / 2.0))}
    assert judge_rate(WALK, shallow)["factor"] is None  # a human gait as declared: the residuals are not enough
    assert judge_rate(ISSUE, shallow)["factor"] == 2.0  # the issue's gait outside the human ranges: named


def test_a_walk_within_the_ranges_of_human_gait_at_either_rate_is_named_by_its_residuals():
    # 158 steps/min, 0.58 m strides: a quick short-stepped walk, humanly possible (and so is 105 at 1.3 m)
    assert judge_rate(relabelled(WALK, 1.5), evidence(1.0))["factor"] is None
    assert judge_rate(relabelled(WALK, 1.5), evidence(1.5))["factor"] == 1.5


@pytest.mark.parametrize("f", [2.0, 0.5, 1.5, 2.0 / 3.0])
def test_with_the_gyroscope_and_the_accelerometer_each_factor_is_named(f):
    assert judge_rate(relabelled(WALK, f), evidence(f))["factor"] == f


def test_residuals_that_prefer_the_declared_rate_overrule_the_gait():
    assert judge_rate(ISSUE, evidence(1.0))["factor"] is None


def test_a_gait_that_no_rate_makes_human_is_no_evidence():
    crawl = {**WALK, "stride_length_m": 0.004, "speed_m_s": 0.004, "clearance_m": 0.0, "rolling_m_rad": 0.02}
    verdict = judge_rate(crawl, None)
    assert not verdict["gait_informative"] and verdict["factor"] is None


def test_the_likely_rate_is_a_common_rate_when_one_is_near():
    assert likely_rate(400.2, 2.0) == 200.0 and likely_rate(120.0, 2.0) == 60.0
    assert likely_rate(409.6, 2.0) == 204.8 and likely_rate(240.0, 1.2) == 200.0
    assert likely_rate(100.0, 1.5) == pytest.approx(66.67)  # 64 Hz is 4 % away: not rounded to it


# --------------------------------------------------------------------------- simulated walks, batch and live
@pytest.fixture(scope="module")
def walk() -> Recording:
    return simulate("rectangle", n_strides=24, rate=100.0, noise=NoiseModel(seed=4))


@pytest.mark.parametrize("f, stamps", [(2.0, True), (1.5, True), (0.5, False)])
def test_a_walk_read_at_the_wrong_rate_is_named_once_with_the_real_rate_batch_and_live(walk, f, stamps):
    t = walk.t / f if stamps else np.arange(walk.n) / (100.0 * f)  # without time stamps: only the declared rate
    rec = Recording(t=t, acc=walk.acc, gyr=walk.gyr, meta={"name": "relabelled"})
    res, found = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(rec))
    finding = res.diagnostics["sensor"]["plausibility"]["rate"]
    assert finding["likely_rate"] == 100.0 and finding["rate_factor"] == pytest.approx(f, rel=0.01)
    declared = f"{100.0 * f:.4g}"
    assert len(found) == 1 and f"probably sampled at 100 Hz, not {declared} Hz" in found[0], found
    assert "time: {rate: 100}" in found[0] and "--option rate=100" in found[0]
    assert finding["strides"]["cadence_steps_min"] == pytest.approx(120.0 * f, rel=0.02)  # the simulator's 120
    stream = Stream(Pipeline.from_dict(BASE), rate=rec.rate)
    _, live = _sensor_warnings(lambda: stream.run(rec, chunk=np.array([1, 23, 7, 64])))
    online = stream.sensor["plausibility"]["rate"]
    assert (online["likely_rate"], online["until_sample"]) == (finding["likely_rate"], finding["until_sample"])
    assert len(live) == 1 and "probably sampled at 100 Hz" in live[0]


#: The simulator's run (3.2 m/s) and slow walk (0.85 m/s) with its physical foot model and sensor noise.
SIMULATED = {"run": {"path": "run", "n_strides": 16}, "slow walk": {"path": "mixed_speed", "speeds": [("slow", 12)]}}


@pytest.mark.parametrize("rate", [100.0, 250.0, 400.0])
@pytest.mark.parametrize("gait", sorted(SIMULATED))
def test_a_simulated_run_or_slow_walk_is_named_only_when_relabelled_and_then_with_its_rate(gait, rate):
    rec = simulate(profile="physical", rate=rate, noise=NoiseModel(seed=2), magnetometer=False, **SIMULATED[gait])
    res, found = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(rec))
    assert "plausibility" not in res.diagnostics["sensor"] and not found  # at its real rate: no warning at all
    for f in (2.0, 0.5):
        relabelled = Recording(t=rec.t / f, acc=rec.acc, gyr=rec.gyr, meta={"name": "relabelled"})
        res, found = _sensor_warnings(lambda r=relabelled: Pipeline.from_dict(BASE).run(r))
        assert res.diagnostics["sensor"]["plausibility"]["rate"]["likely_rate"] == rate
        assert sum(f"probably sampled at {rate:g} Hz" in m for m in found) == 1


def test_a_run_whose_foot_is_never_still_is_named_from_its_quietest_instants_batch_and_live():
    """The simulator's run with a 25 Hz vibration of 1 rad/s on its gyroscope from the first step on: no instant of it
    is as still as a walking foot's, so only a running foot's bounds give the gyroscope-accelerometer evidence."""
    from ..filters.test_consistency_scan import vibrating

    rec = simulate(path="run", n_strides=16, rate=100.0, profile="physical", noise=NoiseModel(seed=2),
                   magnetometer=False)
    gyr = vibrating(rec)
    for f in (1.0, 2.0):
        relabelled = Recording(t=rec.t / f, acc=rec.acc, gyr=gyr, meta={"name": "relabelled"})
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = Pipeline.from_dict(BASE).run(relabelled)
            stream = Stream(Pipeline.from_dict(BASE), rate=relabelled.rate)
            stream.run(relabelled, chunk=np.array([1, 23, 7, 64]))
        found = [str(w.message) for w in caught]
        # expected besides: the detector's stance guard (its angular-rate threshold finds no stance in the vibration)
        assert all("found no stance" in m or "probably sampled at" in m for m in found), found
        named = [m for m in found if "probably sampled at" in m]
        if f == 1.0:
            assert "plausibility" not in res.diagnostics["sensor"] and not named
            continue
        assert res.diagnostics["sensor"]["plausibility"]["rate"]["likely_rate"] == 100.0
        assert stream.sensor["plausibility"]["rate"]["likely_rate"] == 100.0
        assert len(named) == 2 and all("by a running foot's bounds" in m for m in named)  # batch, then live


def test_with_too_few_strides_from_the_detector_the_gait_is_measured_between_quiet_instants(walk):
    """A detector that found no stance at all in the simulated walk read at 1.5 times its rate: the strides between the
    foot's quiet instants (the gyroscope-accelerometer scan's swings) are the gait weighed."""
    from footzoo.core.plausibility import GaitScan
    from footzoo.filters.consistency import ConsistencyScan

    t = walk.t / 1.5
    evidence = ConsistencyScan(walk.rate * 1.5)
    evidence.push_recording(t, walk.acc, walk.gyr)
    scan = GaitScan("relabelled", evidence=evidence)
    scan.push(np.arange(walk.n), t, walk.acc, walk.gyr, np.zeros(walk.n, dtype=bool), np.zeros((walk.n, 3)))
    with pytest.warns(SensorWarning, match="between the foot's quiet instants") as caught:
        finding = scan.finish()["rate"]
    assert len(caught) == 1 and "probably sampled at 100 Hz, not 150 Hz" in str(caught[0].message)
    gait = finding["strides"]
    assert gait["between"] == "quiet instants" and finding["until_sample"] is None
    assert gait["cadence_steps_min"] == pytest.approx(120.0 * 1.5, rel=0.02)  # the simulator's 120, read 1.5× fast


def test_the_same_walk_at_its_real_rate_is_not_named(walk):
    res, found = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(walk))
    assert "plausibility" not in res.diagnostics["sensor"] and not found


def test_a_gyroscope_in_rad_s_declared_as_deg_s_is_named_batch_and_live(walk):
    rec = Recording(t=walk.t, acc=walk.acc, gyr=walk.gyr * math.pi / 180.0, meta={"name": "deg"})
    res, found = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(rec))
    finding = res.diagnostics["sensor"]["plausibility"]["gyro_unit"]
    assert finding["turning_samples"] == 0 and finding["peak_if_rad_s"] == pytest.approx(
        np.abs(walk.gyr).max() * math.sqrt(3), rel=0.8)  # read as rad/s, a walking foot's rate
    assert len(found) == 1 and "look like rad/s declared as deg/s" in found[0] and "gyr_unit: rad/s" in found[0]
    assert "acc_scale" not in res.diagnostics["sensor"]  # the quiet gyroscope says nothing of the accelerometer
    stream = Stream(Pipeline.from_dict(BASE), rate=rec.rate)
    _, live = _sensor_warnings(lambda: stream.run(rec, chunk=np.array([5, 40])))
    assert stream.sensor["plausibility"]["gyro_unit"]["sample"] == finding["sample"]
    assert len(live) == 1


def test_a_gyroscope_that_measures_no_rotation_is_not_named_a_unit(walk):
    """Noise alone (a dead or disconnected gyroscope) reads too little in any unit: not "declare gyr_unit: rad/s"."""
    noise = np.random.default_rng(0).normal(0.0, 0.0017, walk.gyr.shape)  # rad/s: 0.1 °/s RMS, a MEMS gyroscope's
    rec = Recording(t=walk.t, acc=walk.acc, gyr=noise, meta={"name": "dead"})
    res, found = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(rec))
    finding = res.diagnostics["sensor"]["plausibility"]["gyro_unit"]
    assert not finding["unit_explains"] and finding["peak_if_rad_s"] < 0.5
    named = [m for m in found if "turns faster than" in m]
    assert len(named) == 1 and "No unit explains it" in named[0] and "gyr_unit: rad/s" not in named[0]


def test_a_slowly_turning_foot_in_rad_s_declared_as_deg_s_is_still_named_a_unit():
    """PyShoe's crawl turns its foot slowly (1.6 rad/s at most in its first 2 s of motion): declared in deg/s, it
    reads too little, and the unit explains it."""
    from pathlib import Path

    import footzoo

    path = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "pyshoe_vicon" / "2018-02-09-11-18-04.mat"
    if not path.exists():
        pytest.skip("../shared/data absent")
    crawl = footzoo.load(path)
    rec = Recording(t=crawl.t, acc=crawl.acc, gyr=crawl.gyr * math.pi / 180.0, meta={"name": "crawl"})
    res, found = _sensor_warnings(lambda: Pipeline.from_yaml("recommended").run(rec))
    finding = res.diagnostics["sensor"]["plausibility"]["gyro_unit"]
    assert finding["unit_explains"] and 0.5 < finding["peak_if_rad_s"] < 2.0
    assert any("declare gyr_unit: rad/s" in m for m in found)


def _frozen_acc(rec: Recording, lo: int, hi: int, name: str) -> Recording:
    """``rec`` with its accelerometer repeating sample ``lo``'s reading up to ``hi`` (a dropout; it is warned)."""
    acc = rec.acc.copy()
    acc[lo:hi] = acc[lo]
    with pytest.warns(SensorWarning, match="the accelerometer repeats one reading"):
        return Recording(t=rec.t, acc=acc, gyr=rec.gyr, meta={"name": name})


# slow: the live stream of the Kalman flagship on a 20-stride walk (about 13 s on a fresh install)
@pytest.mark.slow
def test_a_dropped_out_accelerometer_is_not_named_a_wrong_rate_batch_and_live():
    """Its frozen reading makes the gait implausible after it, which the dropout explains (and its warning names)."""
    straight = simulate(n_strides=20, rate=100.0, noise=NoiseModel(seed=1))
    rec = _frozen_acc(straight, 300, 1200, "dropout")
    # recommended: its Kalman filter turns the frozen stretch into short, fast strides (named ½ the rate before)
    res, found = _sensor_warnings(lambda: Pipeline.from_yaml("recommended").run(rec))
    assert "rate" not in res.diagnostics["sensor"].get("plausibility", {}) and not any("sampled at" in m for m in found)
    stream = Stream(Pipeline.from_yaml("recommended_live"), rate=rec.rate)
    _, live = _sensor_warnings(lambda: stream.run(rec, chunk=np.array([1, 23, 7, 64])))
    assert stream.sensor["frozen"][0]["first"] == 300  # the live scan found the dropout
    assert "rate" not in stream.sensor.get("plausibility", {}) and not any("sampled at" in m for m in live)


def test_a_wrong_rate_before_a_dropout_is_still_named(walk):
    """The strides before the dropout are judged: ×2 is named with the real rate."""
    half = Recording(t=walk.t / 2.0, acc=walk.acc, gyr=walk.gyr, meta={"name": "relabelled"})
    rec = _frozen_acc(half, walk.n - 200, walk.n - 20, "relabelled")
    res, found = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(rec))
    finding = res.diagnostics["sensor"]["plausibility"]["rate"]
    assert finding["likely_rate"] == 100.0 and finding["until_sample"] < walk.n - 200
    assert sum("probably sampled at 100 Hz" in m for m in found) == 1


def test_a_short_walk_with_its_gyroscope_in_rad_s_declared_as_deg_s_is_named_at_its_end_batch_and_live():
    """Four strides move for 1.4 s, too little for the first test; the peak of the whole recording then decides."""
    short = simulate(n_strides=4, rate=100.0, noise=NoiseModel(seed=3))
    res, found = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(short))
    assert "plausibility" not in res.diagnostics["sensor"] and not found  # as declared: nothing to name
    rec = Recording(t=short.t, acc=short.acc, gyr=short.gyr * math.pi / 180.0, meta={"name": "deg"})
    res, found = _sensor_warnings(lambda: Pipeline.from_dict(BASE).run(rec))
    finding = res.diagnostics["sensor"]["plausibility"]["gyro_unit"]
    assert 0.3 < finding["moving_s"] < 2.0  # decided on the short test, not after 2 s of motion
    assert finding["peak_if_rad_s"] == pytest.approx(np.linalg.norm(short.gyr, axis=1).max())
    assert len(found) == 1 and "never exceeds 0.35 rad/s" in found[0] and "gyr_unit: rad/s" in found[0]
    stream = Stream(Pipeline.from_dict(BASE), rate=rec.rate)
    _, live = _sensor_warnings(lambda: stream.run(rec, chunk=np.array([5, 40])))
    assert stream.sensor["plausibility"]["gyro_unit"]["peak_if_rad_s"] == finding["peak_if_rad_s"] and len(live) == 1
