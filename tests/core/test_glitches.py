"""Glitch bursts of 1 to 20 samples in the gyroscope and the accelerometer: flagged wherever they are, batch and
live; a clipped axis is saturation, not a glitch; the real recordings hold none.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import footzoo
from footzoo.core.data import Recording
from footzoo.core.errors import FootzooWarning, SensorWarning
from footzoo.core.sanity import ACC_GLITCH_JUMP, GLITCH_JUMP, GLITCH_MAX_LEN, SignalScan, find_bursts
from footzoo.sim import NoiseModel, simulate

from ..conftest import GAPS_BRIDGED, data_file


@pytest.fixture(scope="module")
def walk() -> Recording:
    return simulate(n_strides=4, rate=100.0, noise=NoiseModel(seed=1))


def _sensor_warnings(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn()
    return out, [str(w.message) for w in caught if issubclass(w.category, SensorWarning)]


@pytest.mark.parametrize("length", [4, 7, 12, 20])
@pytest.mark.parametrize("rate", [50.0, 100.0, 200.0])
def test_a_long_gyroscope_burst_is_flagged_wherever_it_is_batch_and_live(length, rate):
    rec = simulate(n_strides=4, rate=rate, noise=NoiseModel(seed=3))
    starts = range(int(2.5 * rate), rec.n - int(2 * rate), max(1, int(rate // 9)))  # stances and swings alike
    for k, height in zip(starts, np.resize([30.0, -35.0, 40.0], len(starts)), strict=True):
        gyr = rec.gyr.copy()
        gyr[k:k + length, k % 3] += height
        assert find_bursts(gyr, GLITCH_JUMP).tolist() == list(range(k, k + length)), (k, height)
    gyr = rec.gyr.copy()
    gyr[starts[0]:starts[0] + length, 1] += 32.0
    faulty, found = _sensor_warnings(lambda: Recording(t=rec.t, acc=rec.acc, gyr=gyr, meta={"name": "burst"}))
    assert faulty.meta["sanity"]["gyro_glitches"] == list(range(starts[0], starts[0] + length))
    assert "saturation" not in faulty.meta["sanity"]
    assert any(f"(bursts of 1 to {GLITCH_MAX_LEN} samples," in m and f"at sample(s) {starts[0]} (" in m for m in found)
    scan = SignalScan()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SensorWarning)
        for a, b in zip(range(0, rec.n, 13), range(13, rec.n + 13, 13), strict=True):
            scan.push(rec.t[a:b], rec.acc[a:b], gyr[a:b])
    assert scan.report["gyro_glitches"] == faulty.meta["sanity"]["gyro_glitches"]


@pytest.mark.parametrize("length", [4, 10, 20])
def test_a_long_accelerometer_burst_is_flagged(walk, length):
    acc = walk.acc.copy()
    k = int(np.searchsorted(walk.t, 3.7))
    acc[k:k + length] += [0.0, 0.0, -1500.0]
    rec, found = _sensor_warnings(lambda: Recording(t=walk.t, acc=acc, gyr=walk.gyr, meta={"name": "burst"}))
    assert rec.meta["sanity"]["acc_glitches"] == list(range(k, k + length))
    assert any(f"accelerometer spike(s) standing more than {ACC_GLITCH_JUMP:g} m/s² off the signal around them" in m
               and f"at sample(s) {k} (" in m for m in found)


def test_a_dip_is_reported_by_its_height_off_the_signal_not_by_its_magnitude(walk):
    """IPOL 8-6_lf: a 2-sample dip from 12.5 rad/s to -5.5 rad/s and back; |ω| there (7.3) is below the bound."""
    gyr = walk.gyr.copy()
    k = int(np.searchsorted(walk.t, 3.3))
    gyr[k - 1:k + 3] = [[12.5, -5.9, -2.3], [-5.5, -4.7, -0.6], [-6.2, -4.1, -3.0], [12.2, -3.7, -2.7]]
    rec, found = _sensor_warnings(lambda: Recording(t=walk.t, acc=walk.acc, gyr=gyr, meta={"name": "dip"}))
    assert rec.meta["sanity"]["gyro_glitches"] == [k, k + 1]
    message = next(m for m in found if "gyroscope spike" in m)
    # off the line from (12.5, -5.9, -2.3) to (12.2, -3.7, -2.7), a third and two thirds of the way: hand-computed
    first = np.linalg.norm(np.subtract([-5.5, -4.7, -0.6], [12.4, -5.1667, -2.4333]))
    second = np.linalg.norm(np.subtract([-6.2, -4.1, -3.0], [12.3, -4.4333, -2.5667]))
    assert f"{k} (t = {walk.t[k]:.3f} s, |ω| = 7.3 rad/s, {first:.1f} rad/s off)" in message
    assert f"{k + 1} (t = {walk.t[k + 1]:.3f} s, |ω| = 8.0 rad/s, {second:.1f} rad/s off)" in message
    assert "standing more than 15 rad/s off the signal around them" in message and first > 15 and second > 15


def test_a_clipped_axis_is_saturation_not_a_glitch_and_a_burst_is_not_clipping(walk):
    rail = 0.8 * float(np.abs(walk.gyr[:, 1]).max())  # the swing's rate clipped at the sensor's range
    clipped, found = _sensor_warnings(lambda: Recording(
        t=walk.t, acc=walk.acc, gyr=np.column_stack([walk.gyr[:, 0], np.clip(walk.gyr[:, 1], -rail, rail),
                                                     walk.gyr[:, 2]]), meta={"name": "clipped"}))
    assert "saturation" in clipped.meta["sanity"] and "gyro_glitches" not in clipped.meta["sanity"]
    assert not any("spike" in m for m in found)
    gyr = walk.gyr.copy()
    k = int(np.searchsorted(walk.t, 3.3))
    gyr[k:k + 15, 0] = 34.9  # a burst of one value (a stuck packet) stands out of the signal: a glitch
    stuck, found = _sensor_warnings(lambda: Recording(t=walk.t, acc=walk.acc, gyr=gyr, meta={"name": "stuck"}))
    assert stuck.meta["sanity"]["gyro_glitches"] == list(range(k, k + 15))
    assert any("15 isolated gyroscope spike(s)" in m for m in found), found


def test_bursts_longer_than_the_limit_are_not_called_glitches(walk):
    gyr = walk.gyr.copy()
    k = int(np.searchsorted(walk.t, 3.3))
    gyr[k:k + GLITCH_MAX_LEN + 1, 1] += 40.0
    assert find_bursts(gyr, GLITCH_JUMP).tolist() == []


# PyShoe's trials have gaps in their time stamps, which the reader bridges (expected warning)
@pytest.mark.filterwarnings(GAPS_BRIDGED)
@pytest.mark.slow
def test_no_glitch_of_any_length_in_the_real_recordings():
    import glob

    folder = data_file("pyshoe_vicon")
    recs = [footzoo.load(f) for f in sorted(glob.glob(str(folder / "*.mat")))]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FootzooWarning)
        for name in ("imu_sample.csv", "imu_sample_not_rotated.csv"):
            recs += [footzoo.load(data_file("gaitmap_example", name), foot=f) for f in ("left", "right")]
        recs += [footzoo.load(data_file("xio_gait_tracking", "short_walk.csv"))]
        recs += [footzoo.load(p) for p in sorted(data_file("koroglu_gcp").glob("*.csv"))]
    for rec in recs:
        # margin: nothing even at half the limits (the closest, PyShoe's running trials, stand 0.45 of them high)
        assert not len(find_bursts(rec.gyr, GLITCH_JUMP / 2)), rec.name
        assert not len(find_bursts(rec.acc, ACC_GLITCH_JUMP / 2)), rec.name
        assert "gyro_glitches" not in rec.meta.get("sanity", {}) and "acc_glitches" not in rec.meta.get("sanity", {})
