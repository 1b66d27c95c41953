"""The Kalman filter's normalised innovation squared (NIS): the consistency check that needs no ground truth.

Checked against what the compiled loop did not compute: filterpy's stacked innovation ``y`` and its covariance
``S`` in the reference loop (``νᵀ S⁻¹ ν``; the compiled loop sums ``ν_a² / s_a`` over sequential scalar rows,
equal for a diagonal R), and χ² draws for the summary.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from footzoo import Pipeline
from footzoo.evaluation.metrics import nis_summary
from footzoo.sim import NoiseModel, simulate


@pytest.fixture(scope="module")
def noisy_walk():
    return simulate("rectangle", length=8.0, width=4.0, rate=100.0, noise=NoiseModel(seed=4), seed=4)


@pytest.mark.parametrize("config", ["nguyen2016", "duong2015_zupt_height"])
def test_the_compiled_nis_equals_filterpys_stacked_innovation(config, noisy_walk):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fast = Pipeline.from_yaml(config).run(noisy_walk, covariance=True, engine="fast").diagnostics
        ref = Pipeline.from_yaml(config).run(noisy_walk, covariance=True, engine="reference").diagnostics
    np.testing.assert_array_equal(fast["nis_rows"], ref["nis_rows"])
    assert (fast["nis_rows"] > 0).sum() > 100 and fast["nis"].max() > 1e-3
    np.testing.assert_allclose(fast["nis"], ref["nis"], rtol=1e-6, atol=1e-12)
    assert fast["consistency"]["rows"] == int(fast["nis_rows"].sum())


def test_the_summary_of_chi_square_draws_is_one_per_row_and_95_percent_inside():
    rng = np.random.default_rng(0)
    rows = rng.choice([1, 3, 6], size=20000)
    nis = rng.chisquare(rows)
    s = nis_summary(np.r_[0.0, nis], np.r_[0, rows])  # a sample without an update does not count
    assert s["updates"] == 20000 and s["rows"] == rows.sum()
    assert s["nis_per_row"] == pytest.approx(1.0, abs=0.02)
    assert s["nis_inside"] == pytest.approx(0.95, abs=0.01)
    cautious = nis_summary(nis / 10, rows)  # a filter whose S is ten times too large
    assert cautious["nis_per_row"] == pytest.approx(0.1, abs=0.005) and cautious["nis_inside"] < 0.6


def test_without_updates_the_summary_is_nan_not_a_number():
    s = nis_summary(np.zeros(5), np.zeros(5))
    assert np.isnan(s["nis_per_row"]) and s["updates"] == 0
