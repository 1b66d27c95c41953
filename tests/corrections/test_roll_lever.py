"""The zero-velocity update's rolling-stance noise (``zupt`` / ``ekf_zupt`` ``roll_lever``)."""

from __future__ import annotations

import numpy as np
import pytest

from footzoo import ConfigError, Pipeline
from footzoo.corrections.ekf_zupt import ZUPT, zero_velocity_measure
from footzoo.evaluation.metrics import stride_errors
from footzoo.filters.measurement import ACC_BIAS, ATT, GYRO_BIAS, POS, VEL, Context, Rows, V
from footzoo.sim import NoiseModel, simulate


def _config(lever: float, **detector) -> dict:
    return {"orientation": {"type": "ins"}, "detector": {"type": "shoe", **detector},
            "corrections": [{"type": "zupt", "velocity_std": 0.03, "roll_lever": lever}]}


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=16, profile="physical", rate=100.0, noise=NoiseModel(seed=2))


def test_the_velocity_rows_by_hand():
    """σ² = σ_v² + (ℓ |ω|)² on each velocity row: ℓ = 0.2 m, |ω|² = 0.3² + 0.4² + 1.2² = 1.69 rad²/s²."""
    model = ZUPT(velocity_std=0.03, roll_lever=0.2).model(None)
    nav = np.zeros(16)
    nav[V:V + 3] = [0.1, -0.2, 0.05]
    idx = np.full(5, -1)
    idx[[ATT, POS, VEL]] = [0, 3, 6]
    z, H, R = np.zeros(12), np.zeros((12, 9)), np.zeros(12)
    ctx = Context(0, 0.0, nav, np.array([0.3, -0.4, 1.2]), np.array([0.0, 0.0, -9.81]), True, idx, model.par,
                  model.mem, np.zeros(0))
    m = zero_velocity_measure(ctx, Rows(z, H, R, 0))
    assert m == 3
    np.testing.assert_allclose(R[:3], 0.03**2 + 0.2**2 * 1.69, rtol=1e-15)
    np.testing.assert_array_equal(z[:3], nav[V:V + 3])
    np.testing.assert_array_equal(H[:3, 6:9], np.eye(3))
    assert idx[GYRO_BIAS] == idx[ACC_BIAS] == -1  # the 9-state filter: no bias rows
    # out of stance: nothing
    assert zero_velocity_measure(ctx._replace(stance=False), Rows(z, H, R, 0)) == 0


def test_a_lever_of_zero_is_the_papers_update_to_the_bit(walk):
    plain = {"orientation": {"type": "ins"}, "detector": {"type": "shoe"},
             "corrections": [{"type": "zupt", "velocity_std": 0.03}]}
    np.testing.assert_array_equal(Pipeline.from_dict(_config(0.0)).run(walk).pos,
                                  Pipeline.from_dict(plain).run(walk).pos)


def test_compiled_loop_equals_the_reference_with_the_lever_on(walk):
    p = Pipeline.from_dict({**_config(0.2), "smoother": "rts"})
    ref, fast = p.run(walk, engine="reference"), p.run(walk, engine="fast")
    assert np.max(np.abs(fast.pos - ref.pos)) <= 1e-9 * max(np.abs(ref.pos).max(), 1.0)


def test_a_stance_that_includes_the_roll_no_longer_shortens_the_strides(walk):
    """A generous detector (SHOE at 3e6: 53 % stance, the truth 49 %) takes the simulated foot's rolling
    after initial contact and before toe-off for stance; the zero-velocity update then stops a sensor that
    still moves, and the strides come out wrong (measured 7 mm long, against 4 mm short with the right
    stance). Weighing those samples by the foot's rotation gives the length back (against the simulator's
    true strides); where the stance is right (SHOE at 3e4) the foot does not turn and the lever changes
    nothing."""

    def bias(threshold: float, lever: float) -> float:
        e = stride_errors(Pipeline.from_dict(_config(lever, threshold=threshold)).run(walk).steps, walk.truth.steps)
        assert e["matched_strides"] == e["ref_strides"] == 16
        return e["stride_length_mean_error_m"]

    right = bias(3e4, 0.0)
    assert abs(right) < 0.01
    assert bias(3e4, 0.2) == pytest.approx(right, abs=1e-4)
    off, on = bias(3e6, 0.0), bias(3e6, 0.2)
    assert abs(off - right) > 0.01  # more than 1 cm per stride off the right stance's length (measured 11 mm)
    assert abs(on - right) < 0.002


@pytest.mark.parametrize("lever", [-0.1, 2.0, float("nan")])
def test_a_lever_outside_its_range_is_refused_with_its_unit(lever):
    with pytest.raises(ConfigError, match="roll_lever"):
        Pipeline.from_dict(_config(lever))
