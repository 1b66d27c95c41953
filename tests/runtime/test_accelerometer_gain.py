"""An accelerometer that reads too much at rest (a gain error) is scaled back to g from the still start.

The IPOL gait set's left-foot MTw reads 10.04-10.44 m/s² at rest; simulated here as a walk whose
specific force is 5 % too large, ending with a 6 s stand like the IPOL trials. Truth is the
simulator's.
"""

import numpy as np
import pytest

import footzoo
from footzoo import Recording
from footzoo.core.errors import SensorWarning
from footzoo.runtime import alignment
from footzoo.sim import simulate


@pytest.fixture(scope="module")
def walk():
    return simulate(path="straight", n_strides=4, rate=100.0, profile="physical", magnetometer=False, stand_end=6.0)


@pytest.fixture(scope="module")
def pipe():
    return footzoo.Pipeline.from_yaml("recommended")


def _hot(rec, gain=1.05):
    return Recording(t=rec.t, acc=rec.acc * gain, gyr=rec.gyr, meta={"name": "hot"}, truth=rec.truth)


def _end_error(res, rec):
    return (res.pos[-1] - res.pos[0]) - (rec.truth.pos[-1] - rec.truth.pos[0])


def test_a_calibrated_accelerometer_is_used_as_it_is(walk, recwarn):
    assert alignment.accelerometer_gain(walk.t, walk.acc, walk.gyr, 9.81) == 1.0
    assert alignment.accelerometer_gain(walk.t, walk.acc * 1.02, walk.gyr, 9.81) == 1.0  # inside the tolerance
    assert not [w for w in recwarn if issubclass(w.category, SensorWarning)]


def test_a_gain_error_is_measured_from_the_still_start(walk):
    with pytest.warns(SensorWarning, match=r"reads 10\.30\d m/s² in the still start .* \+5\.0 % off g = 9\.81"):
        gain = alignment.accelerometer_gain(walk.t, walk.acc * 1.05, walk.gyr, 9.81, name="hot")
    assert gain == pytest.approx(1 / 1.05, rel=1e-9)


def test_a_walk_read_5_percent_high_ends_where_the_truth_ends(walk, pipe):
    with pytest.warns(SensorWarning, match="gain"):
        res = pipe.run(_hot(walk))
    assert res.diagnostics["acc_gain"]["gain"] == pytest.approx(1 / 1.05, rel=1e-9)
    assert np.abs(_end_error(res, walk)).max() < 0.01  # noise-free: the scaled signal is the true one
    assert res.stance[walk.t > walk.t[-1] - 5.0].all()  # the final stand is stance


def test_without_the_gain_the_stand_is_missed_and_the_track_climbs(walk, pipe, monkeypatch):
    """The cause of the IPOL climbs: the stance test compares ‖f‖ with g, so the stand is taken for a swing."""
    monkeypatch.setattr(alignment, "ACC_GAIN_TOLERANCE", 1.0)
    with pytest.warns(SensorWarning, match="misses this stillness"):
        res = pipe.run(_hot(walk))
    assert "acc_gain" not in res.diagnostics
    assert res.stance[walk.t > walk.t[-1] - 5.0].mean() < 0.1
    assert -_end_error(res, walk)[2] > 1.0  # metres up (NED: height = -down)


def test_a_stream_scales_the_specific_force_as_a_batch_run(walk):
    live_pipe = footzoo.Pipeline.from_yaml("recommended_live")
    hot = _hot(walk)
    with pytest.warns(SensorWarning, match="gain"):
        batch = live_pipe.run(hot)
    with pytest.warns(SensorWarning, match="gain"):
        live = footzoo.Stream(live_pipe).run(hot, chunk=200)
    np.testing.assert_allclose(live["pos"], batch.pos, atol=1e-6)
    assert np.abs(_end_error(batch, walk)).max() < 0.01


def test_a_walk_with_dropped_packets_and_a_gain_error_stands_still_at_its_end(walk, pipe, monkeypatch):
    """IPOL-like packet loss (runs of 1 to 7 packets, about 11 % of the samples, stand included) on the 5 % walk:
    the final stand is stance and the estimate stays within a centimetre there (the truth stays put; measured
    1.1 cm of creep over the 5 s, the filter's zero-velocity residual after the holed swings), where without the
    gain it climbs by metres."""
    rng = np.random.default_rng(0)
    keep = np.ones(walk.n, bool)
    k = 60  # the still start's first 0.6 s kept whole: the attitude and the gain are taken there
    while k < walk.n - 10:
        n = int(rng.integers(1, 8))
        keep[k:k + n] = False
        k += n + int(rng.integers(3, 40))
    assert 0.08 < 1 - keep.mean() < 0.15
    with pytest.warns(footzoo.FootzooWarning, match="bridged"):
        holed = Recording(t=walk.t[keep], acc=walk.acc[keep] * 1.05, gyr=walk.gyr[keep], meta={"name": "holed"})
    with pytest.warns(SensorWarning, match="gain"):
        res = pipe.run(holed)
    stand = holed.t > walk.t[-1] - 5.0
    assert res.stance[stand].all()
    assert np.linalg.norm(res.pos[stand] - res.pos[stand][0], axis=1).max() < 0.02  # truth: 0
    assert len(res.steps) == len(pipe.run(walk).steps)  # every stride of the intact walk is found
    monkeypatch.setattr(alignment, "ACC_GAIN_TOLERANCE", 1.0)
    with pytest.warns(SensorWarning, match="misses this stillness"):
        climbs = pipe.run(holed)
    assert -(climbs.pos[-1, 2] - climbs.pos[stand][0, 2]) > 1.0  # metres up during the stand


def _restless(walk, gain, jolt=0.0, noise=0.0):
    """The walk read ``gain`` too high, its still start shaken: a forward jolt (m/s²) every other sample and white
    noise (m/s², each axis) while the gyroscope stays quiet."""
    acc = walk.acc * gain
    start, stop = alignment.first_still_window(walk.t, walk.gyr, 0.5, 0.6)
    acc[start:stop:2, 0] += jolt
    acc[start:stop] += np.random.default_rng(3).normal(0.0, noise, (stop - start, 3))
    return acc


@pytest.mark.parametrize("gain, jolt, noise, reading", [
    (1.05, 3.0, 0.0, r"10\.\d+ m/s² .* \+[56]\.\d % off g"),  # a slide: ‖f‖ scatters by about 1.5 m/s²
    (1.20, 0.0, 0.6, r"11\.\d+ m/s² .* \+2\d\.\d % off g"),  # 1.2 g with 0.6 m/s² of noise
])
def test_a_restless_start_far_from_g_is_named_not_corrected(walk, gain, jolt, noise, reading):
    """Quiet gyroscope, moving foot: ‖f‖ scatters, its mean is not gravity, nothing is scaled, and the warning says
    so with the reading, its scatter and the fixes (the reader's unit, a calibration, a still start)."""
    acc = _restless(walk, gain, jolt, noise)
    with pytest.warns(SensorWarning, match=reading + r".*scatters by \d\.\d\d m/s² \(\d+\.\d % of g.*too restless.*"
                                           r"not corrected.*acc_unit.*at rest for init\.duration = 0\.5 s"):
        assert alignment.accelerometer_gain(walk.t, acc, walk.gyr, 9.81) == 1.0


def test_a_restless_start_near_g_says_nothing(walk, recwarn):
    """A start that moves while the gyroscope is quiet but whose mean reads g (PyShoe 2017-11-22-11-52-02: +1.9 %,
    scattering by 7 % of g) has nothing to correct and nothing to say."""
    assert alignment.accelerometer_gain(walk.t, _restless(walk, 1.0, 0.0, 0.6), walk.gyr, 9.81) == 1.0
    assert not [w for w in recwarn if issubclass(w.category, SensorWarning)]


def test_the_step_by_step_api_prepares_a_walk_read_5_percent_high_as_run_does(walk, pipe, recwarn):
    """prepare, detect, guard, orient and navigate give run's stance, attitude and track, through run's own stages:
    the same warning, the same acc_gain entry; a raw recording given to a step is prepared the same way."""
    hot = _hot(walk)
    with pytest.warns(SensorWarning, match="gain"):
        res = pipe.run(hot)
    with pytest.warns(SensorWarning, match="gain"):
        rec, q0, diagnostics = pipe.prepare(hot)
    assert diagnostics == {"acc_gain": res.diagnostics["acc_gain"]}
    np.testing.assert_array_equal(hot.acc, walk.acc * 1.05)  # the caller's recording stays
    recwarn.clear()
    stance, _ = pipe.guard(rec, pipe.detect(rec))  # a prepared recording is taken as it is: no second warning
    nav = pipe.navigate(rec, stance, q0, pipe.orient(rec, stance, q0))
    assert not [w for w in recwarn if issubclass(w.category, SensorWarning)]
    np.testing.assert_array_equal(stance, res.stance)
    np.testing.assert_array_equal(nav["quat"], res.quat)
    np.testing.assert_array_equal(nav["pos"], res.pos)
    assert np.abs(_end_error(res, walk)).max() < 0.01
    with pytest.warns(SensorWarning, match="gain"):
        raw = pipe.guard(hot, pipe.detect(hot))[0]
    np.testing.assert_array_equal(raw, res.stance)
    recwarn.clear()
    again = pipe.run(rec)  # run takes a prepared recording as it is too: not scaled twice, no second warning
    assert not [w for w in recwarn if issubclass(w.category, SensorWarning)]
    np.testing.assert_array_equal(again.pos, res.pos)


def test_a_reading_far_from_g_is_not_rescaled_as_a_gain(walk):
    """A gain is a few per cent: a still start at 0.3 g is a unit or a column, never multiplied up to g (a swapped
    recording was once rescaled by 9674)."""
    with pytest.warns(SensorWarning, match=r"-70.0 % off g .* no scale-factor error is that large, so the specific "
                                           r"force is not rescaled"):
        gain = alignment.accelerometer_gain(walk.t, walk.acc * 0.3, walk.gyr, 9.81, name="far")
    assert gain == 1.0


def test_no_still_period_because_the_columns_are_swapped_is_said_so(walk):
    """With the accelerometer read as the gyroscope, |ω| reads g throughout: no still period, named as a swap."""
    from footzoo import RecordingError

    with pytest.raises(RecordingError, match=r"which is g = 9.81 m/s² in number; the accelerometer's and the "
                                             r"gyroscope's columns look swapped"):
        alignment.first_still_window(walk.t, walk.acc, 0.5, 0.6)
