"""Every registered detector behaves the same at 50–1000 Hz and from 0.3 to 4 m/s with its default setting."""

import numpy as np
import pytest

from footzoo.evaluation.metrics import stance_scores
from footzoo.plugins.registry import available

from .sims import GAITS, RATES, walk

DETECTORS = sorted(name for name, cls in available("detector").items() if not getattr(cls, "needs_truth", False))


@pytest.mark.parametrize("name", DETECTORS)
@pytest.mark.parametrize("gait", list(GAITS))
def test_stance_f1_is_stable_across_rates(name, gait):
    cls = available("detector")[name]
    f1 = {}
    for rate in RATES:
        rec = walk(gait, rate)
        f1[rate] = stance_scores(cls().detect(rec.t, rec.acc, rec.gyr).stance_, rec.truth.stance)["f1"]
    assert min(f1.values()) > 0.85, f1
    assert max(f1.values()) - min(f1.values()) < 0.06, f1


@pytest.mark.parametrize("rate", [50.0, 200.0, 1000.0])
def test_windowed_acc_change_is_taken_over_the_papers_sample_interval(rate):
    """A 2 Hz, 5 m/s² sway: its change per 10 ms (Duong & Suh's 100 Hz) is the same statistic at any rate.

    Between consecutive samples it would shrink with the rate (a tenth at 1000 Hz) while B_a did not.
    """
    from footzoo.detectors.windowed import Windowed

    def stat(r):
        t = np.arange(int(4 * r)) / r
        acc = np.zeros((t.size, 3))
        acc[:, 0] = 5.0 * np.sin(2 * np.pi * 2.0 * t)
        acc[:, 2] = -9.81
        return Windowed().detect(t, acc, np.zeros((t.size, 3))).acc_statistic_[t.size // 4: 3 * t.size // 4].max()

    assert stat(rate) == pytest.approx(stat(100.0), rel=0.03)
    assert stat(100.0) == pytest.approx(5.0 * 2 * np.pi * 2.0 * 0.01, rel=0.03)


def test_windowed_agrees_with_itself_on_a_real_walk_taken_at_half_the_rate():
    """PyShoe walking trial (200 Hz) and every other sample of it (100 Hz): the stance masks agree.

    Measured on the first 8 walking trials: 0.3–2.9 % of samples differ (2.6–7.1 % with the change
    between consecutive samples).
    """
    import scipy.io

    from footzoo.detectors.windowed import Windowed

    from ..conftest import data_file

    m = scipy.io.loadmat(data_file("pyshoe_vicon", "2017-11-22-11-28-03.mat"))
    imu, t = m["imu"], m["ts"].ravel()
    s200 = Windowed().detect(t, imu[:, :3], imu[:, 3:]).stance_
    s100 = Windowed().detect(t[::2], imu[::2, :3], imu[::2, 3:]).stance_
    assert np.mean(s200[::2] != s100) < 0.035
