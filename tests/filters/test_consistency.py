"""Position uncertainty from the Kalman covariance, NEES and the vertical-error metrics."""

from __future__ import annotations

import numpy as np
import pytest

from footzoo.evaluation.metrics import position_nees, vertical_errors
from footzoo.runtime.pipeline import Pipeline
from footzoo.sim import NoiseModel, simulate


def test_vertical_errors_of_a_hand_made_walk():
    n = 101
    ref = np.zeros((n, 3))
    ref[:, 0] = np.linspace(0.0, 10.0, n)  # 10 m north on flat ground
    est = ref.copy()
    est[:, 2] = -np.linspace(0.0, 0.05, n)  # climbs 5 cm (NED: d negative is up)
    v = vertical_errors(est, ref)
    assert v["height_end_error_m"] == pytest.approx(0.05)
    assert v["height_end_error_pct"] == pytest.approx(0.5)
    assert v["height_rms_error_m"] == pytest.approx(np.sqrt(np.mean(np.linspace(0.0, 0.05, n) ** 2)))
    # a closed loop without a reference: the end against the start's height
    assert vertical_errors(est)["height_end_error_m"] == pytest.approx(0.05)
    assert "height_rms_error_m" not in vertical_errors(est)


def test_position_nees_by_hand():
    est = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    ref = np.zeros((2, 3))
    var = np.array([[4.0, 1.0, 1.0], [1.0, 1.0, 0.0]])  # a zero variance is skipped (NaN)
    nees = position_nees(est, ref, var)
    assert nees[0] == pytest.approx(0.25) and np.isnan(nees[1])


@pytest.fixture(scope="module")
def covariance_run():
    rec = simulate(path="rectangle", length=10.0, width=5.0, rate=100.0, profile="physical", clearance=0.15,
                   noise=NoiseModel(scale=1, seed=0), magnetometer=False)
    return rec, Pipeline.from_yaml("recommended").run(rec, covariance=True)


def test_the_position_standard_deviation_is_the_covariance_diagonal(covariance_run):
    _, res = covariance_run
    sd = res.diagnostics["pos_std"]
    # recommended's error state: attitude (3), position (3), velocity (3)
    assert res.diagnostics["P_diag"].shape[1] == 9
    np.testing.assert_array_equal(sd, np.sqrt(res.diagnostics["P_diag"][:, 3:6]))
    np.testing.assert_array_equal(res.samples[["pos_std_n", "pos_std_e", "pos_std_d"]].to_numpy(), sd)
    assert "pos_std_n" not in Pipeline.from_yaml("recommended").run(covariance_run[0]).samples  # only on request


def test_two_sigma_covers_the_true_error_on_the_simulator(covariance_run):
    rec, res = covariance_run
    sd = res.diagnostics["pos_std"]
    truth = rec.truth.pos - rec.truth.pos[0]
    for pos in (res.diagnostics["pos_forward"], res.samples[["pos_n", "pos_e", "pos_d"]].to_numpy()):
        inside = np.abs(pos - pos[0] - truth) <= 2 * sd
        # measured: every sample on every axis (the covariance is conservative: mean NEES 0.1, not 3)
        assert inside.mean(axis=0).min() >= 0.95
