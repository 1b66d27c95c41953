"""The simulated heel strike: its roll through initial contact, and its rate against real feet."""

import numpy as np
import pytest

from footzoo.evaluation.metrics import reference_steps
from footzoo.sim.gait import HEEL_ROLL, heel_strike_roll
from footzoo.sim.profiles import SmoothRate

from ..conftest import data_file, load_benchmark


def test_smooth_rate_integrates_to_its_angle():
    """Angle, rate and angular acceleration of a knot profile agree with each other (numerical integral and
    derivative) and with the hand-summed areas of its pieces."""
    prof = SmoothRate([-0.1, -0.04, 0.01, 0.035, 0.07], [0.0, 1.5, 1.5, -4.0, 0.0])
    # pieces: (0 + 1.5)/2 · 0.06 + 1.5 · 0.05 + (1.5 − 4)/2 · 0.025 + (−4 + 0)/2 · 0.035
    assert prof.total == pytest.approx(0.045 + 0.075 - 0.03125 - 0.07, abs=1e-15)
    t = np.linspace(-0.15, 0.1, 250_001)
    ang, rate, acc = prof.angle(t)
    np.testing.assert_allclose(ang[1:], np.cumsum((rate[1:] + rate[:-1]) / 2 * np.diff(t)), atol=1e-9)
    np.testing.assert_allclose(np.gradient(rate, t), acc, atol=2e-3 * np.abs(acc).max())
    assert ang[0] == 0.0 and ang[-1] == pytest.approx(prof.total)


@pytest.mark.parametrize("cycle, side", [(1.0, 1), (1.2, -1), (0.75, 1)])
def test_the_heel_strike_roll_returns_flat_and_lands_rolling(cycle, side):
    """Net roll zero (the foot is flat again in the stance), inverting at 1.5 rad/s (at a 1 s cycle) when the heel
    lands, and over before the heel rotation ends (its 0.1 s at a 1 s cycle)."""
    roll = heel_strike_roll(cycle, 0.4 * cycle, 0.1 * cycle, side)
    assert roll.total == pytest.approx(0.0, abs=1e-15)
    _, rate, _ = roll.angle(np.array([0.0]))
    assert rate[0] == pytest.approx(side * HEEL_ROLL[1][1] / cycle)
    assert roll.t[-1] <= 0.09 * cycle and roll.t[0] >= -0.2 * cycle


@pytest.mark.slow
def test_the_simulated_heel_strike_turns_like_gaitmaps_feet():
    """Around initial contact the simulated rate behaves as the motion-captured feet of gaitmap's walk (57 ICs).

    Measured (benchmarks/heel_strike.md): |ω| below 1 rad/s for 0 ms at the median gaitmap heel strike and the
    simulated ones (before the foot rolled through heel strike: 23-34 ms); the rate about the two other axes at IC
    1.5 and 1.25 rad/s (walk, stairs) within gaitmap's 10-90 % range 1.06-2.31; the sagittal rate below 1 rad/s
    for 23 and 33 ms, within gaitmap's 10.5-40.5 ms.
    """
    hs = load_benchmark("heel_strike")
    from footzoo.io import load

    path = data_file("gaitmap_example", "imu_sample.csv")
    real = []
    for foot in ("left", "right"):
        rec = load(path, foot=foot)
        real.append(hs.heel_strikes(rec, reference_steps(rec.truth.steps)["largest_pitch_s"].to_numpy(float)))
    real_dwell = np.concatenate([r["dwell_ms"] for r in real])
    real_off = np.concatenate([r["off_sagittal_ic"] for r in real])
    real_sag = np.concatenate([r["dwell_sagittal_ms"] for r in real])
    assert len(real_dwell) == 57
    for name in ("walk", "stairs"):
        sim = hs.simulated(name, 100.0)
        assert np.median(sim["dwell_ms"]) == np.median(real_dwell) == 0.0
        assert sim["dwell_ms"].max() <= np.percentile(real_dwell, 90)
        lo, hi = np.percentile(real_off, [10, 90])
        assert lo <= np.median(sim["off_sagittal_ic"]) <= hi
        assert real_sag.min() <= np.median(sim["dwell_sagittal_ms"]) <= real_sag.max()
