"""Kernel inputs seen through read-only views: one compiled variant of a kernel for every caller's arrays."""

import numpy as np
import pytest

from footzoo.analysis import gait_events
from footzoo.filters import consistency
from footzoo.kernels import jit as _jit
from footzoo.kernels.views import read_only
from footzoo.sim import simulate


def test_read_only_is_a_read_only_view_and_leaves_the_callers_array_writable():
    a = np.arange(6.0).reshape(2, 3)
    view = read_only(a)
    assert not view.flags.writeable and view.flags.c_contiguous
    assert np.shares_memory(view, a)  # no copy of a C-contiguous float array
    assert a.flags.writeable
    with pytest.raises(ValueError):
        view[0, 0] = 1.0
    converted = read_only(np.asfortranarray(np.arange(6).reshape(2, 3)))  # another layout and dtype: a copy
    assert converted.dtype == float and converted.flags.c_contiguous and not converted.flags.writeable
    np.testing.assert_array_equal(converted, np.arange(6).reshape(2, 3))


@pytest.mark.skipif(not _jit.HAVE_NUMBA, reason="numba not installed")
def test_writable_and_frozen_inputs_run_the_same_compiled_kernels():
    """A run freezes its recording while it runs (so the kernels a wheel ships are typed on read-only arrays); a
    channel a calibration rescaled, or a user's own arrays, are writable: the same machine code must serve both."""
    rec = simulate(n_strides=6, rate=100.0, profile="physical")
    frozen = {n: read_only(getattr(rec, n)) for n in ("t", "acc", "gyr")}
    writable = {n: getattr(rec, n).copy() for n in ("t", "acc", "gyr")}
    results = []
    for arrays in (frozen, writable):
        scan = consistency.ConsistencyScan(rec.rate)
        scan.push_recording(arrays["t"], arrays["acc"], arrays["gyr"])
        results.append(np.asarray(scan.residuals))
        if arrays is frozen:
            kinds = {k: len(getattr(consistency, k).signatures) for k in ("_residuals", "_swing_gait")}
    assert len(results[0]) >= 4  # the walk's swings were measured
    np.testing.assert_array_equal(results[0], results[1])
    assert {k: len(getattr(consistency, k).signatures) for k in kinds} == kinds  # no second variant compiled

    x = np.sin(np.linspace(0.0, 20.0, 400))
    lo, hi = np.array([0, 100, 250]), np.array([80, 200, 400])
    first = gait_events.segment_argext(read_only(x), lo, hi, largest=True)
    n = len(gait_events._argext_kernel.signatures)
    np.testing.assert_array_equal(gait_events.segment_argext(x.copy(), lo, hi, largest=True), first)
    assert len(gait_events._argext_kernel.signatures) == n
    # the largest sample of each range, by hand
    np.testing.assert_array_equal(first, [lo[i] + np.argmax(x[lo[i]:hi[i]]) for i in range(3)])


@pytest.mark.skipif(not _jit.HAVE_NUMBA, reason="numba not installed")
def test_a_detector_called_on_a_users_arrays_reuses_the_kernels_a_run_compiled():
    """A pipeline hands its detector the recording frozen; a user's analysis code calls ``detect`` on its own arrays."""
    from footzoo.detectors import speed_adaptive_shoe
    from footzoo.detectors.speed_adaptive_shoe import SpeedAdaptiveSHOE

    rec = simulate(n_strides=6, rate=100.0, profile="physical")
    frozen = SpeedAdaptiveSHOE().detect(read_only(rec.t), read_only(rec.acc), read_only(rec.gyr)).stance_
    n = len(speed_adaptive_shoe.swing_speeds.signatures)
    mine = SpeedAdaptiveSHOE().detect(rec.t.copy(), rec.acc.copy(), rec.gyr.copy()).stance_
    assert len(speed_adaptive_shoe.swing_speeds.signatures) == n
    np.testing.assert_array_equal(mine, frozen)
    assert 0.2 < frozen.mean() < 0.8  # a walk: stances and swings
