"""Compiled replacements give the numbers of the numpy code they replaced.

Each ``_reference_*`` below is the previous implementation, kept verbatim, run on
simulated walks (with a magnetic disturbance where it matters) and on random data.
Speed itself: benchmarks/.
"""

import numpy as np
import pytest

from footzoo.core.conventions import GRAVITY
from footzoo.orientation.magnetic import REFERENCE_DURATION, field_norm_and_dip, magnetometer_valid
from footzoo.sim import MagneticDisturbance, NoiseModel, simulate


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
    from footzoo.plugins.registry import build

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
    from footzoo.core.conventions import GRAVITY as G
    from footzoo.detectors.windows import window_moments
    from footzoo.plugins.registry import build

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
    from footzoo.plugins.contract import all_finite

    rng = np.random.default_rng(0)
    big = np.finfo(float).max
    cases = [rng.normal(size=(50, 3)), np.array([1.0, np.nan]), np.array([np.inf, -np.inf]), np.array([big, big]),
             np.array([big, big, np.nan]), np.array([-big, big, 1.0]), np.zeros((0, 3)), np.array([1 + 2j, np.nan]),
             rng.normal(size=(20, 4)).astype(np.float32), np.array([np.inf])]
    for x in cases:
        assert all_finite(x) == bool(np.isfinite(x).all())


def test_the_sample_table_wraps_the_outputs_and_copies_time_and_stance():
    from footzoo.core.table import samples_frame

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


def _reference_segment_argext(x, lo, hi, largest):
    if len(lo) == 0:
        return np.zeros(0, dtype=np.int64)
    lengths = hi - lo
    offsets = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    idx = np.arange(int(lengths.sum()), dtype=np.int64) - np.repeat(offsets - lo, lengths)
    values = x[idx]
    ext = (np.maximum if largest else np.minimum).reduceat(values, offsets)
    hit = np.flatnonzero(values == np.repeat(ext, hi - lo))
    first = hit[np.searchsorted(hit, offsets)]
    return idx[first]


def _reference_gait_events(t, gyr, stances):
    w = np.asarray(gyr, dtype=float)[:, 1]
    n = len(t)
    ts = np.asarray(t, dtype=float)
    dt = np.diff(ts)
    t = ts - 0.5 * np.concatenate([[np.median(dt)], dt])
    k = len(stances) - 1
    a, b = stances[:, 0], stances[:, 1]
    mid = (a + b - 1) // 2
    sw0, sw1 = b[:-1], a[1:]
    p = _reference_segment_argext(w, np.minimum(sw0, n - 1), np.maximum(sw1, sw0 + 1), largest=True)
    to_lo = np.minimum(mid[:-1], p)
    j = _reference_segment_argext(w, to_lo, np.maximum(p, to_lo + 1), largest=False)
    down = np.flatnonzero((w[:-1] > 0.0) & (w[1:] <= 0.0)) + 1
    pos = np.searchsorted(down, p + 1)
    c = down[np.minimum(pos, max(len(down) - 1, 0))] if len(down) else np.full(k, n)
    ok = (pos < len(down)) & (c <= mid[1:]) & (w[p] > 0.0) & (w[j] < 0.0)
    c = np.where(ok, c, 1)
    den_c = w[c - 1] - w[c]
    frac = np.where(ok, w[c - 1] / np.where(ok, den_c, 1.0), 0.0)
    ic = t[c - 1] + frac * (t[c] - t[c - 1])
    # TO: the first sample in (j, p] at or above half the push-off peak (the parabola's vertex), after one below
    jl, jr = np.maximum(j - 1, 0), np.minimum(j + 1, n - 1)
    den = w[jl] - 2.0 * w[j] + w[jr]
    inner = (den > 0) & (jl < j) & (j < jr)
    level = 0.5 * np.minimum(np.where(inner, w[j] - (w[jl] - w[jr]) ** 2 / (8.0 * np.where(inner, den, 1.0)), w[j]),
                             w[j])
    idx, offsets = _ranges(j + 1, np.maximum(p + 1, j + 1))
    seg = np.repeat(np.arange(k), np.maximum(p - j, 0))
    up = np.flatnonzero((w[idx - 1] < level[seg]) & (w[idx] >= level[seg]))
    first = np.searchsorted(up, offsets)
    found = (first < len(up)) & (seg[up[np.minimum(first, max(len(up) - 1, 0))]] == np.arange(k)) if len(up) else \
        np.zeros(k, bool)
    r = np.where(found, idx[up[np.minimum(first, max(len(up) - 1, 0))]] if len(up) else 1, 1)
    ok &= found
    den_r = w[r] - w[r - 1]
    frac_r = np.clip((level - w[r - 1]) / np.where(den_r != 0, den_r, 1.0), 0.0, 1.0)
    to = t[r - 1] + frac_r * (t[r] - t[r - 1])
    to = np.where(ok, to, ts[np.minimum(sw0, n - 1)])
    ic = np.where(ok, ic, ts[np.minimum(sw1, n - 1)])
    return to, ic, ok


def _ranges(lo, hi):
    """Indices of the ranges [lo_i, hi_i) concatenated, and each range's offset."""
    lengths = hi - lo
    offsets = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    return np.arange(int(lengths.sum()), dtype=np.int64) - np.repeat(offsets - lo, lengths), offsets


def test_segment_argext_equals_the_reduceat_code():
    from footzoo.analysis.gait_events import segment_argext

    rng = np.random.default_rng(4)
    x = np.round(rng.normal(size=2000), 1)  # many ties
    lo = np.sort(rng.integers(0, 1990, 300))
    hi = lo + rng.integers(1, 10, 300)
    # the steps table's highest point: the first minimum of pos_d is the first maximum of -pos_d
    np.testing.assert_array_equal(segment_argext(x, lo, hi, False), _reference_segment_argext(-x, lo, hi, True))
    for largest in (True, False):
        np.testing.assert_array_equal(segment_argext(x, lo, hi, largest), _reference_segment_argext(x, lo, hi, largest))
        np.testing.assert_array_equal(segment_argext(x[::2], lo // 2, np.maximum(hi // 2, lo // 2 + 1), largest),
                                      _reference_segment_argext(x[::2], lo // 2, np.maximum(hi // 2, lo // 2 + 1),
                                                                largest))


@pytest.mark.parametrize("scenario", [
    {"path": "mixed_speed", "rate": 100.0}, {"path": "stairs", "rate": 200.0}, {"path": "rectangle", "rate": 50.0}])
@pytest.mark.parametrize("flip", [False, True])
def test_gait_events_equal_the_vectorised_code(scenario, flip):
    """The compiled searches and the mid-interval times of the event samples give the vectorised events to the bit."""
    from footzoo.analysis.gait_events import detect_gait_events
    from footzoo.analysis.strides import real_stances
    from footzoo.plugins.registry import build

    r = simulate(profile="physical", noise=NoiseModel(seed=6), n_strides=30, **scenario)
    t = r.t + np.cumsum(np.random.default_rng(1).uniform(0.0, 1e-4, len(r.t)))  # uneven intervals
    gyr = -r.gyr if flip else r.gyr  # upside down: no pattern, the fallbacks
    stance = build("detector", {"type": "shoe"}).detect(t, r.acc, gyr).stance_
    st = real_stances(stance, r.truth.pos)
    # a one-sample stance at sample 0 (the first interval's median) before the first one, moved past it
    first = np.vstack([[0, 1], np.column_stack([np.maximum(st[:, 0], 2), st[:, 1]])])
    for stances in (st, first, st[:2]):
        ev = detect_gait_events(t, gyr, stances)
        to, ic, ok = _reference_gait_events(t, gyr, stances)
        np.testing.assert_array_equal(ev.from_rate, ok)
        np.testing.assert_array_equal(ev.to, to)
        np.testing.assert_array_equal(ev.ic, ic)
    assert 0 < ok.sum() or flip


def _reference_dated_and_online_states(candidate, min_samples, initial=True):
    c = np.asarray(candidate, dtype=bool)
    n = c.shape[0]
    g = max(int(min_samples), 1)
    idx = np.arange(n)

    def runs(x):
        change = np.flatnonzero(x[1:] != x[:-1]) + 1
        starts = np.concatenate([[0], change]).astype(np.int64)
        return starts, np.diff(np.concatenate([starts, [n]]))

    def fill(x, switch_at, value_at):
        src = np.full(n, -1)
        src[switch_at] = idx[value_at]
        src = np.maximum.accumulate(src)
        return np.where(src >= 0, x[np.maximum(src, 0)], initial)

    starts, lengths = runs(c)
    long_starts = starts[lengths >= g]
    online = fill(c, long_starts + g - 1, long_starts)
    short_still = c[starts] & (lengths < g) & (starts > 0) & (starts + lengths < n)
    still = c & ~np.repeat(short_still, lengths)
    starts, lengths = runs(still)
    long_starts = starts[lengths >= g]
    dated = fill(still, long_starts, long_starts)
    return dated, online


@pytest.mark.parametrize("min_samples", [0, 1, 2, 3, 5, 12])
@pytest.mark.parametrize("initial", [True, False])
def test_two_state_machine_equals_the_vectorised_code(min_samples, initial):
    from footzoo.detectors.runs import dated_and_online_states

    rng = np.random.default_rng(min_samples)
    cases = [rng.random(3000) < p for p in (0.1, 0.5, 0.9)]
    cases += [np.repeat(rng.random(400) < 0.5, rng.integers(1, 9, 400)), np.zeros(7, bool), np.ones(7, bool),
              np.array([True]), np.array([False, True, True, False])]
    for c in cases:
        got = dated_and_online_states(c, min_samples, initial)
        want = _reference_dated_and_online_states(c, min_samples, initial)
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
        assert got[0].dtype == got[1].dtype == bool
