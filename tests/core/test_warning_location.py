"""A footzoo warning names the user's line (the call into footzoo), however deep inside footzoo it was raised."""

import warnings

import numpy as np
import pandas as pd
import pytest

from footzoo import Pipeline, Recording
from footzoo.core.errors import CalibrationWarning, FootzooWarning, user_stacklevel
from footzoo.sim import NoiseModel, simulate


def _caught(call, category):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        call()
    found = [w for w in caught if issubclass(w.category, category)]
    assert found, f"no {category.__name__} given"
    return found


def _gap_recording():
    t = np.delete(np.arange(400) / 100.0, range(200, 205))  # a 60 ms gap at 100 Hz: bridged with a warning
    df = pd.DataFrame({"t": t, **{f"acc_{a}": [0.0, 0.0, -9.81][i] for i, a in enumerate("xyz")},
                       **{f"gyr_{a}": 0.0 for a in "xyz"}})
    return Recording.from_dataframe(df)


def test_a_recordings_warning_names_the_line_that_built_it():
    for w in _caught(_gap_recording, FootzooWarning):
        assert w.filename == __file__  # _gap_recording's line, not footzoo/core/data.py


def test_a_runs_warning_names_the_line_that_ran_it():
    rec = simulate(path="straight", n_strides=4, rate=50.0, noise=NoiseModel(scale=1, seed=0))
    pipe = Pipeline.from_yaml("yun2012")  # a straight walk cannot calibrate the magnetometer: a CalibrationWarning
    for w in _caught(lambda: pipe.run(rec), CalibrationWarning):
        assert w.filename == __file__


def test_the_stack_level_counts_the_frames_inside_footzoo():
    assert user_stacklevel() == 1  # called here, outside footzoo: warnings.warn's own default
    with pytest.warns(FootzooWarning) as caught:
        warnings.warn("here", FootzooWarning, stacklevel=user_stacklevel())
    assert caught[0].filename == __file__
