"""Compiled replacements give the numbers of the numpy code they replaced.

Each ``_reference_*`` below is the previous implementation, kept verbatim, run on
simulated walks (with a magnetic disturbance where it matters) and on random data.
Speed itself: benchmarks/.
"""

import numpy as np
import pytest

from footzoo.conventions import GRAVITY
from footzoo.orientation.magnetic import REFERENCE_DURATION, field_norm_and_dip, magnetometer_valid
from footzoo.sim import MagneticDisturbance, NoiseModel, simulate

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")


def _reference_magnetometer_valid(t, acc, mag, still, norm_tolerance, dip_tolerance):
    mn, dip = field_norm_and_dip(acc, mag)
    still = np.asarray(still, dtype=bool)
    n_lead = int(np.argmin(still)) if not still.all() else still.size
    ref = (t - t[0] <= REFERENCE_DURATION) & (np.arange(t.size) < n_lead)
    if ref.sum() < 2:
        ref = t - t[0] <= 0.5
    norm_ref = float(np.median(mn[ref]))
    dip_ref = float(np.median(dip[ref]))
    quiet = np.abs(np.linalg.norm(acc, axis=1) - GRAVITY) < 0.1 * GRAVITY
    valid = np.abs(mn - norm_ref) <= norm_tolerance * norm_ref
    valid &= ~quiet | (np.abs(dip - dip_ref) <= dip_tolerance)
    return valid, norm_ref, dip_ref


@pytest.fixture(scope="module")
def disturbed_walk():
    dist = MagneticDisturbance(field=(0.0, 0.25, 0.0), north=(35.0, 41.0), east=(-1.0, 3.0))
    return simulate(path="rectangle", profile="physical", rate=100.0, disturbance=dist, noise=NoiseModel(seed=3))


@pytest.mark.parametrize("lead", [0, 1, 60, 10_000])
@pytest.mark.parametrize("tolerances", [(0.1, np.radians(5.0)), (0.02, np.radians(1.0)), (0.3, 0.2)])
def test_magnetometer_check_equals_the_numpy_code(disturbed_walk, lead, tolerances):
    r = disturbed_walk
    from footzoo.registry import build

    still = build("detector", {"type": "windowed"}).detect(r.t, r.acc, r.gyr).stance_.copy()
    still[:lead] = True  # leading still runs of several lengths, also none and all
    if lead == 0:
        still[0] = False
    got = magnetometer_valid(r.t, r.acc, r.mag, still, *tolerances)
    want = _reference_magnetometer_valid(r.t, r.acc, r.mag, still, *tolerances)
    assert 0 < want[0].sum() < len(r.t)  # both outcomes occur
    np.testing.assert_array_equal(got[0], want[0])
    assert got[1:] == want[1:]


def test_magnetometer_check_equals_the_numpy_code_on_random_fields():
    rng = np.random.default_rng(7)
    n = 20_000
    t = np.cumsum(rng.uniform(0.004, 0.006, n))
    acc = rng.normal([0.0, 0.0, -GRAVITY], 1.0, (n, 3))
    mag = rng.normal([0.2, 0.0, 0.4], 0.03, (n, 3))
    for still in (rng.random(n) < 0.5, np.ones(n, bool), np.zeros(n, bool)):
        got = magnetometer_valid(t, acc, mag, still, 0.1, np.radians(5.0))
        want = _reference_magnetometer_valid(t, acc, mag, still, 0.1, np.radians(5.0))
        np.testing.assert_array_equal(got[0], want[0])
        assert got[1:] == want[1:]


@pytest.mark.parametrize("name", ["shoe", "ared", "amvd", "mbgtd", "huang_stance", "adaptive_shoe"])
@pytest.mark.parametrize("rate", [100.0, 200.0])
def test_skog_statistics_in_the_window_pass_equal_the_tests_on_the_moments(name, rate):
    """The fused window pass gives the statistic of ``test(window_moments(...))``, the previous path, to the bit."""
    from footzoo.conventions import GRAVITY as G
    from footzoo.detectors.windows import window_moments
    from footzoo.registry import build

    r = simulate(n_strides=20, rate=rate, profile="physical", path="mixed_speed", noise=NoiseModel(seed=5))
    det = build("detector", {"type": name, "window": 0.04}).detect(r.t, r.acc, r.gyr)
    m = window_moments(np.ascontiguousarray(r.acc), np.ascontiguousarray(r.gyr), det.window_samples_, G)
    np.testing.assert_array_equal(det.statistic_, det.test(m))


def test_a_subclass_with_its_own_test_gets_the_moments():
    from footzoo.detectors.shoe import SHOE

    class Louder(SHOE):
        def test(self, m):
            return 2.0 * super().test(m)

    r = simulate(n_strides=5, rate=100.0, profile="physical", noise=NoiseModel(seed=1))
    np.testing.assert_array_equal(Louder().detect(r.t, r.acc, r.gyr).statistic_,
                                  2.0 * SHOE().detect(r.t, r.acc, r.gyr).statistic_)


def test_the_finite_check_without_a_temporary_equals_isfinite_all():
    from footzoo.plugin import _all_finite

    rng = np.random.default_rng(0)
    big = np.finfo(float).max
    cases = [rng.normal(size=(50, 3)), np.array([1.0, np.nan]), np.array([np.inf, -np.inf]), np.array([big, big]),
             np.array([big, big, np.nan]), np.array([-big, big, 1.0]), np.zeros((0, 3)), np.array([1 + 2j, np.nan]),
             rng.normal(size=(20, 4)).astype(np.float32), np.array([np.inf])]
    for x in cases:
        assert _all_finite(x) == bool(np.isfinite(x).all())


def test_the_sample_table_wraps_the_outputs_and_copies_time_and_stance():
    from footzoo._table import samples_frame

    r = simulate(n_strides=5, rate=100.0, profile="physical", noise=NoiseModel(seed=2))
    q, pos, vel = r.truth.quat.copy(), r.truth.pos.copy(), r.truth.vel.copy()
    acc = np.zeros_like(pos)
    frame = samples_frame(r.t, q, pos, vel, acc, r.truth.stance)
    assert np.shares_memory(frame["qx"].to_numpy(), q) and np.shares_memory(frame["vel_d"].to_numpy(), vel)
    assert not np.shares_memory(frame["t"].to_numpy(), r.t)
    assert not np.shares_memory(frame["stance"].to_numpy(), r.truth.stance)
    np.testing.assert_array_equal(frame[["pos_n", "pos_e", "pos_d"]].to_numpy(), pos)
    with pytest.raises(ValueError, match="shape"):
        samples_frame(r.t, q[:, :3], pos, vel, acc, r.truth.stance)
