"""The PyShoe reader carries what the dataset documents: the right foot, an upside-down trial that still works."""

import numpy as np
import pytest

from footzoo.core.errors import FootzooWarning
from footzoo.evaluation.metrics import pyshoe_error
from footzoo.io import load
from footzoo.runtime.pipeline import Pipeline
from tests.conftest import data_file

from ..conftest import STANCES_GUARDED, UPSIDE_DOWN_TRIAL


def test_pyshoe_sensor_is_on_the_right_foot_so_huang2016_runs():
    rec = load(data_file("pyshoe_vicon", "2017-11-22-11-22-03.mat"))
    assert rec.meta["foot"] == "right"
    # the side is known, so the FPA is computed; the walk circles the room, so every footprint is on a turn
    with pytest.warns(FootzooWarning, match="the walk turns at 2[0-9] of 2[0-9] footprints"):
        res = Pipeline.from_yaml("huang2016").run(rec)
    assert len(res.steps) > 10 and res.steps["fpa_rad"].isna().all()
    # the trajectory itself (PyShoe's best on this trial: 0.032 m)
    assert pyshoe_error(res.pos, rec.truth.pos) < 0.1


# windowed misses the stances of part of this unusual trial; the guard marks them (expected warning)
# its subject: the sensor is mounted upside down, which the mounting report names (expected warning)
@pytest.mark.filterwarnings(UPSIDE_DOWN_TRIAL)
@pytest.mark.filterwarnings(STANCES_GUARDED)
def test_upside_down_trial_is_aligned_from_gravity():
    rec = load(data_file("pyshoe_vicon", "2018-02-22-10-09-36.mat"))
    assert rec.acc[:50, 2].mean() > 9.0  # mounted upside down: +g on z at rest
    res = Pipeline.from_yaml("duong2015_zupt").run(rec)
    quat = res.samples[["qw", "qx", "qy", "qz"]].to_numpy()
    roll = np.degrees(np.abs(res.samples["roll"].to_numpy()[:50]))
    assert np.all(roll > 170)  # the estimate knows the sensor is upside down
    assert np.linalg.norm(quat[0]) == pytest.approx(1.0)
    # and the track is as good as on the upright walking trials (PyShoe's best there: 0.059 m)
    assert pyshoe_error(res.pos, rec.truth.pos) < 0.15
