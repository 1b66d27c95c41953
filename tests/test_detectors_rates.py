"""Every registered detector behaves the same at 50–1000 Hz and from 0.3 to 4 m/s with its default setting."""

import pytest

from footzoo.metrics import stance_scores
from footzoo.registry import available

from .detector_sims import GAITS, RATES, walk

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
