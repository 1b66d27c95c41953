"""Skog et al. 2010's SHOE, ARED, AMVD and MBGTD: hand-derived cases, simulator truth, PyShoe's masks."""

import numpy as np
import pytest

from footzoo import Pipeline, Recording
from footzoo.core.context import RunContext
from footzoo.core.conventions import GRAVITY
from footzoo.detectors import AMVD, ARED, MBGTD, SHOE
from footzoo.evaluation.metrics import stance_scores
from footzoo.orientation.madgwick import Madgwick

from ..conftest import data_file
from .sims import GAITS, RATES, walk

SIGMA_A, SIGMA_G = 0.01, np.radians(0.1)


def still(n=200, rate=100.0):
    t = np.arange(n) / rate
    return t, np.tile([0.0, 0.0, -GRAVITY], (n, 1)), np.zeros((n, 3))


def test_a_still_sensor_gives_zero_statistics():
    t, acc, gyr = still()
    acc = acc @ np.array([[1, 0, 0], [0, 0.6, -0.8], [0, 0.8, 0.6]])  # tilted, still |a| = g
    for cls in (SHOE, ARED, AMVD, MBGTD):
        d = cls().detect(t, acc, gyr)
        np.testing.assert_allclose(d.statistic_, 0.0, atol=1e-6)
        assert d.stance_.all()


def test_the_tests_compare_with_the_runs_gravity():
    """A still sensor reading g = 9.78 m/s² (a pipeline's ``gravity: 9.78``): zero against the run's g; against
    9.81 the SHOE and MBGTD terms are (0.03 m/s²)²/σ_a² = 9 (hand-derived)."""
    t, acc, gyr = still()
    acc *= 9.78 / GRAVITY
    ctx = RunContext(rate=100.0, gravity=9.78)
    for cls in (SHOE, MBGTD):
        assert cls().detect(t, acc, gyr, ctx=ctx).gravity_ == 9.78
        np.testing.assert_allclose(cls().detect(t, acc, gyr, ctx=ctx).statistic_, 0.0, atol=1e-6)
        np.testing.assert_allclose(cls().detect(t, acc, gyr).statistic_, 0.03**2 / SIGMA_A**2, rtol=1e-6)
    rec = Recording(t=t, acc=acc, gyr=gyr)
    assert Pipeline(orientation=Madgwick(), detector=SHOE(), gravity=9.78).detect(rec).gravity_ == 9.78


def test_constant_rotation_gives_rate_squared_over_sigma():
    t, acc, gyr = still()
    gyr[:] = [0.3, -0.4, 0.0]  # |ω| = 0.5 rad/s
    expected = 0.25 / SIGMA_G**2
    np.testing.assert_allclose(ARED().detect(t, acc, gyr).statistic_, expected, rtol=1e-12)
    np.testing.assert_allclose(SHOE().detect(t, acc, gyr).statistic_, expected, rtol=1e-9)
    np.testing.assert_allclose(AMVD().detect(t, acc, gyr).statistic_, 0.0, atol=1e-6)  # blind to rotation


def test_a_single_spike_gives_the_window_variance():
    """One sample off by Δ in a W-sample window: Σ‖y − ȳ‖² = Δ²(W − 1)/W, |a| − g = Δ at that sample only."""
    t, acc, gyr = still(rate=200.0)
    delta = 0.5
    acc[100, 0] += delta
    d = AMVD(window=0.025).detect(t, acc, gyr)  # W = 5 samples
    w = d.window_samples_
    assert w == 5
    np.testing.assert_allclose(d.statistic_[98:103], delta**2 * (w - 1) / w**2 / SIGMA_A**2, rtol=1e-6)
    assert d.statistic_[97] < 1e-6 and d.statistic_[103] < 1e-6
    m = MBGTD(window=0.025).detect(t, acc, gyr)
    excess = np.hypot(GRAVITY, delta) - GRAVITY
    np.testing.assert_allclose(m.statistic_[98:103], excess**2 / w / SIGMA_A**2, rtol=1e-9)


def test_shoe_matches_its_definition_on_random_data():
    """The moment expansion equals the textbook sum Σ ‖y_a − g ȳ/‖ȳ‖‖²/σ_a² + ‖y_ω‖²/σ_ω² (centred window)."""
    rng = np.random.default_rng(1)
    n, w = 60, 5
    t = np.arange(n) / 200.0
    acc = np.array([0.5, -0.3, -GRAVITY]) + rng.normal(scale=2.0, size=(n, 3))
    gyr = rng.normal(scale=1.0, size=(n, 3))
    stat = SHOE(window=w / 200.0).detect(t, acc, gyr).statistic_
    for k in range(n):
        idx = np.clip(np.arange(k - w // 2, k - w // 2 + w), 0, n - 1)
        u = acc[idx].mean(axis=0)
        u = GRAVITY * u / np.linalg.norm(u)
        ref = np.mean(np.sum((acc[idx] - u) ** 2, axis=1) / SIGMA_A**2 + np.sum(gyr[idx] ** 2, axis=1) / SIGMA_G**2)
        assert stat[k] == pytest.approx(ref, rel=1e-9)


@pytest.mark.parametrize("cls", [SHOE, ARED, AMVD, MBGTD])
@pytest.mark.parametrize("gait", list(GAITS))
def test_stance_against_simulator_truth_at_every_rate(cls, gait):
    """Per-sample stance F1 vs simulator truth at 50–1000 Hz and 0.3–4 m/s with one setting."""
    f1 = []
    for rate in RATES:
        rec = walk(gait, rate)
        f1.append(stance_scores(cls().detect(rec.t, rec.acc, rec.gyr).stance_, rec.truth.stance)["f1"])
    assert min(f1) > 0.9
    assert max(f1) - min(f1) < 0.06


@pytest.mark.parametrize(
    "cls, key", [(SHOE, "zv_shoe_opt"), (ARED, "zv_ared_opt"), (AMVD, "zv_amvd_opt"), (MBGTD, "zv_mbgtd_opt")]
)
@pytest.mark.parametrize("trial", ["2017-11-22-11-22-03", "2017-11-27-11-11-24"])
def test_statistic_agrees_with_pyshoes_own_detector(cls, key, trial):
    """PyShoe's mask of the same detector at its per-trial optimum threshold is matched by some threshold.

    PyShoe decides over non-overlapping 5-sample blocks and re-tunes γ per trial,
    so its masks are not reproducible with one γ; what must agree is the
    statistic's shape: the best F1 over a threshold grid.
    """
    import scipy.io

    m = scipy.io.loadmat(data_file("pyshoe_vicon", f"{trial}.mat"))
    imu, t = m["imu"], m["ts"].ravel()
    ref = m[key].ravel().astype(bool)
    stat = cls().detect(t, imu[:, :3], imu[:, 3:]).statistic_
    best = max(stance_scores(stat < g, ref)["f1"] for g in np.logspace(1, 7, 25))
    assert best > 0.88
